#include "agglomerate/agglomerate_preview.h"

#include <algorithm>

#include "common/preview_renderer.h"
#include "rocklab/render/image_io.h"

namespace rocklab::experiments::agglomerate {

namespace {
// Linear blend from blue (smallest radius) to orange (largest).
render::Rgb radiusColour(double radius, double smallest, double largest) {
  const double span = largest - smallest;
  const float t = span > 0 ? static_cast<float>((radius - smallest) / span) : 1.0f;
  const render::Rgb small{0.20f, 0.40f, 0.80f}, large{0.90f, 0.55f, 0.20f};
  return {small.r + t * (large.r - small.r), small.g + t * (large.g - small.g),
          small.b + t * (large.b - small.b)};
}
}  // namespace

void writeAgglomeratePreview(const std::filesystem::path& png,
                             const std::vector<geometry::Sphere>& spheres) {
  double smallest = spheres.empty() ? 0 : spheres.front().radius, largest = smallest, reach = 0;
  for (const geometry::Sphere& s : spheres) {
    smallest = std::min(smallest, s.radius);
    largest = std::max(largest, s.radius);
    reach = std::max(reach, s.centre.norm() + s.radius);
  }
  const double L = std::max(2.0 * reach, 1e-6), shift = detail::sideBySideShift(L);
  render::Renderer renderer = detail::sideBySideRenderer(L);
  render::FrameDescription f;
  f.background = render::kBackdrop;
  for (const geometry::Sphere& s : spheres) {
    const render::Rgb c = radiusColour(s.radius, smallest, largest);
    f.spheres.push_back(
        {s.centre - geometry::Vec3(shift, 0, 0), s.radius, c, geometry::Vec3::Zero()});
    if (s.centre.y() >= 0)
      f.spheres.push_back(
          {s.centre + geometry::Vec3(shift, 0, 0), s.radius, c, geometry::Vec3::Zero()});
  }
  render::writePng(png, renderer.render(f));
}

}  // namespace rocklab::experiments::agglomerate
