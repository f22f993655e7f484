// Particle sizes from a top photograph (track/particle_sizing.h): rendered spheres
// of known diameter lying on a dark tray, seen by the camera that rendered them.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "rocklab/render/renderer.h"
#include "rocklab/track/particle_sizing.h"

using rocklab::geometry::Camera;
using rocklab::geometry::Vec3;
namespace render = rocklab::render;
namespace track = rocklab::track;

namespace {

Camera topCamera() {
  Camera camera = Camera::withFieldOfView(1280, 960, 25.0);
  camera.lookAt(Vec3(0.02, 0.01, 1.2), Vec3(0.02, 0.01, 0.0), Vec3(0, 1, 0));
  return camera;
}

// A sizing station's dome light: the spheres lit nearly evenly up to their outline.
// (Under the camera's lamp alone, render::RenderOptions' default, a sphere's outline
// fades into the tray and these spheres come out about 7 % small.)
render::RenderOptions domeLight() {
  render::RenderOptions o;
  o.ambient = 0.9f;
  o.diffuse = 0.1f;
  o.specular = 0.0f;
  return o;
}

render::FrameDescription tray(const std::vector<std::pair<Vec3, double>>& spheres) {
  render::FrameDescription f;
  f.polygons.push_back({{{-0.4, -0.3, 0}, {0.4, -0.3, 0}, {0.4, 0.3, 0}, {-0.4, 0.3, 0}}, {0.08f, 0.08f, 0.09f}, 1.0f});
  for (const auto& [xy, r] : spheres) f.spheres.push_back({Vec3(xy.x(), xy.y(), r), r, render::kGreyPebble, Vec3::Zero()});
  return f;
}

// The particle whose label holds the projection of `centre`, or null.
const track::SizedParticle* at(const track::SizingResult& s, const Camera& camera, const Vec3& centre) {
  const auto px = camera.project(centre);
  const int label = s.labels.at<int>(static_cast<int>(std::lround(px.y())), static_cast<int>(std::lround(px.x())));
  for (const auto& p : s.particles)
    if (p.label == label) return &p;
  return nullptr;
}

}  // namespace

TEST_CASE("image sizing gives lone spheres their diameter and splits touching ones at their contact", "[track]") {
  const Camera camera = topCamera();
  // Lone spheres of 8 to 28 mm across the view (off axis too), and a touching pair of 20 and 12 mm.
  std::vector<std::pair<Vec3, double>> spheres = {{Vec3(-0.15, -0.1, 0), 0.004}, {Vec3(0.0, 0.0, 0), 0.007},
                                                  {Vec3(0.16, 0.11, 0), 0.010}, {Vec3(-0.12, 0.12, 0), 0.014},
                                                  {Vec3(0.15, -0.12, 0), 0.0055}};
  const double big = 0.010, small = 0.006;
  // Touching on the tray: horizontal distance between centres at heights big and small.
  const double gap = std::sqrt((big + small) * (big + small) - (big - small) * (big - small));
  spheres.push_back({Vec3(0.05, -0.05, 0), big});
  spheres.push_back({Vec3(0.05 + gap, -0.05, 0), small});
  render::Renderer renderer(camera, domeLight());
  const cv::Mat image = renderer.render(tray(spheres));
  const track::SizingResult s = track::sizeParticles(image, camera, Vec3::Zero(), Vec3::UnitZ());
  REQUIRE(s.particles.size() == spheres.size());
  for (const auto& [xy, r] : spheres) {
    const Vec3 centre(xy.x(), xy.y(), r);
    const track::SizedParticle* p = at(s, camera, centre);
    REQUIRE(p != nullptr);
    INFO("sphere of " << 2e3 * r << " mm: equivalent " << 1e3 * p->equivalent_diameter_m << " mm, Feret "
                      << 1e3 * p->feret_min_m << "-" << 1e3 * p->feret_max_m << " mm");
    // One pixel is about 0.41 mm here: a lone sphere within 3 % (or a third of a pixel
    // for the smallest), the touching pair within 6 % (their border is drawn, not seen).
    const bool paired = r == big || r == small;
    CHECK(std::abs(p->equivalent_diameter_m - 2 * r) < (paired ? 0.06 : 0.03) * 2 * r);
    CHECK(std::abs(p->feret_max_m - 2 * r) < (paired ? 0.08 : 0.05) * 2 * r + 0.0004);
    CHECK(p->outline_height_m == Approx(0.5 * p->equivalent_diameter_m).epsilon(0.05));
    CHECK_FALSE(p->on_border);
  }
}

TEST_CASE("image sizing on the surface plane alone overstates a sphere by its height", "[track]") {
  // What the half-size plane corrects: sized on the tray plane itself, a 28 mm
  // sphere seen from 1.2 m comes out larger by about (1.2) / (1.2 − 0.014).
  const Camera camera = topCamera();
  render::Renderer renderer(camera, domeLight());
  const cv::Mat image = renderer.render(tray({{Vec3(0.0, 0.0, 0), 0.014}}));
  track::SizingSettings flat;
  flat.outline_iterations = 0;
  const auto on_tray = track::sizeParticles(image, camera, Vec3::Zero(), Vec3::UnitZ(), flat);
  const auto mid = track::sizeParticles(image, camera, Vec3::Zero(), Vec3::UnitZ());
  REQUIRE(on_tray.particles.size() == 1);
  REQUIRE(mid.particles.size() == 1);
  const double ratio = on_tray.particles[0].equivalent_diameter_m / mid.particles[0].equivalent_diameter_m;
  CHECK(ratio == Approx(1.2 / (1.2 - 0.014)).epsilon(0.002));
}

TEST_CASE("image sizing flags a particle cut by the image border and names bad settings", "[track]") {
  const Camera camera = topCamera();
  render::Renderer renderer(camera, domeLight());
  // The view is about 0.53 m wide around x = 0.02: a sphere at its left edge is cut.
  const cv::Mat image = renderer.render(tray({{Vec3(0.02 - 0.266, 0.0, 0), 0.012}}));
  const auto s = track::sizeParticles(image, camera, Vec3::Zero(), Vec3::UnitZ());
  REQUIRE(s.particles.size() == 1);
  CHECK(s.particles[0].on_border);
  CHECK(s.particles[0].equivalent_diameter_m < 0.024);
  track::SizingSettings bad;
  bad.min_peak_px = 0.1;
  CHECK_THROWS_WITH(track::sizeParticles(image, camera, Vec3::Zero(), Vec3::UnitZ(), bad),
                    Catch::Contains("sizing.min_peak_px"));
  CHECK_THROWS_AS(track::sizeParticles(cv::Mat(), camera, Vec3::Zero(), Vec3::UnitZ()), std::invalid_argument);
}
