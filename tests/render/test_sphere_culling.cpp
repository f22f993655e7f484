// The CPU occlusion culler (render/src/sphere_culling.h): its verdict does not depend
// on how many bands of rows it runs at once, and a pixel it trims is really hidden.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include <catch2/catch.hpp>

#include "rocklab/geometry/packing.h"
#include "sphere_culling.h"

using rocklab::render::detail::CameraSphere;
using rocklab::render::detail::Canvas;
using rocklab::render::detail::PixelRect;
using rocklab::render::detail::SphereCuller;

namespace {

// A deep pile of disjoint spheres in front of a 320x240 camera (camera frame, z forward).
std::vector<CameraSphere> pile() {
  rocklab::geometry::Rng rng(7);
  std::vector<double> radii(3000);
  for (double& r : radii) r = rng.uniform(0.003, 0.007);
  const auto centres = rocklab::geometry::randomNonOverlapping(radii, rocklab::geometry::Vec3(-0.1, -0.075, 0.5),
                                                                 rocklab::geometry::Vec3(0.1, 0.075, 0.8), {}, rng);
  std::vector<CameraSphere> out;
  for (std::size_t i = 0; i < centres.size(); ++i)
    out.push_back({static_cast<float>(centres[i].x()), static_cast<float>(centres[i].y()),
                   static_cast<float>(centres[i].z()), static_cast<float>(radii[i])});
  return out;
}

std::vector<std::uint32_t> nearToFar(const std::vector<CameraSphere>& s) {
  std::vector<std::uint32_t> order(s.size());
  std::iota(order.begin(), order.end(), 0u);
  const auto power = [&](std::uint32_t i) {
    return s[i].x * s[i].x + s[i].y * s[i].y + s[i].z * s[i].z - s[i].radius * s[i].radius;
  };
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return power(a) < power(b); });
  return order;
}

// Depth of the first hit of the ray through pixel (u, v) with sphere s, or +inf.
double hit(const CameraSphere& s, const Canvas& c, double u, double v) {
  const double dx = (u - c.cx) / c.fx, dy = (v - c.cy) / c.fy, n2 = dx * dx + dy * dy + 1.0;
  const double b = (s.x * dx + s.y * dy + s.z) / n2;
  const double disc = b * b - ((s.x * s.x + s.y * s.y + s.z * s.z) - s.radius * s.radius) / n2;
  return disc < 0.0 ? INFINITY : b - std::sqrt(disc);
}

}  // namespace

TEST_CASE("the sphere culler gives one verdict for any number of bands and trims only hidden pixels", "[render]") {
  const std::vector<CameraSphere> spheres = pile();
  REQUIRE(spheres.size() == 3000);
  const std::vector<std::uint32_t> order = nearToFar(spheres);
  const Canvas canvas{320, 240, 400.0, 400.0, 159.5, 119.5};
  SphereCuller one(1);
  const std::vector<PixelRect> reference = one.cull(spheres, order, canvas);
  const auto dropped = std::count_if(reference.begin(), reference.end(), [](const PixelRect& r) { return r.empty(); });
  CHECK(dropped > 1500);  // a deep pile: most are hidden, else the culler is not doing its job
  for (int threads : {2, 3, 7, 16}) {
    SphereCuller banded(threads);
    CHECK(banded.cull(spheres, order, canvas) == reference);
  }
  // Every pixel centre a sphere's image covers outside its rectangle (all of them for a
  // dropped sphere) shows a kept sphere in front of it, one whose rectangle holds it.
  int hiddenPixels = 0, trimmedPixels = 0;
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const CameraSphere& s = spheres[i];
    const PixelRect& rect = reference[i];
    const double u0 = canvas.fx * s.x / s.z + canvas.cx, v0 = canvas.fy * s.y / s.z + canvas.cy;
    const double reach = canvas.fx * s.radius / (s.z - s.radius) + 1.0;
    for (int v = static_cast<int>(std::floor(v0 - reach)); v <= static_cast<int>(std::ceil(v0 + reach)); ++v)
      for (int u = static_cast<int>(std::floor(u0 - reach)); u <= static_cast<int>(std::ceil(u0 + reach)); ++u) {
        if (u < 0 || v < 0 || u >= canvas.width || v >= canvas.height) continue;
        if (!rect.empty() && u >= rect.u0 && u <= rect.u1 && v >= rect.v0 && v <= rect.v1) continue;
        const double mine = hit(s, canvas, u, v);
        if (!std::isfinite(mine)) continue;
        double nearest = INFINITY;
        for (std::size_t k = 0; k < spheres.size(); ++k) {
          const PixelRect& r = reference[k];
          if (!r.empty() && u >= r.u0 && u <= r.u1 && v >= r.v0 && v <= r.v1)
            nearest = std::min(nearest, hit(spheres[k], canvas, u, v));
        }
        ++(rect.empty() ? hiddenPixels : trimmedPixels);
        REQUIRE(nearest < mine);
      }
  }
  CHECK(hiddenPixels > 1000);
  CHECK(trimmedPixels > 1000);  // kept spheres lose their hidden parts too
}
