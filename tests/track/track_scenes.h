#pragma once
// Synthetic frames and rendered scenes shared by the track tests and the track benchmark.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/packing.h"
#include "rocklab/render/calibration_target.h"
#include "rocklab/render/frame.h"
#include "support/cameras.h"

namespace rocklab::track::test {

using geometry::Camera;
using geometry::Vec2;
using geometry::Vec3;
using rocklab::test::kObliqueChuteView;
using rocklab::test::labCamera;

inline constexpr double kFrameRate = rocklab::test::kLabFrameRate;  // frames/s
inline const cv::Scalar kPaintedRed(40, 35, 190);  // BGR of a red marker in a photo

/// A grey frame (level 120, Gaussian sensor noise of `noise` grey levels, seeded).
inline cv::Mat greyFrame(cv::Size size, double noise, std::uint64_t seed) {
  cv::Mat frame(size, CV_8UC3, cv::Scalar(120, 120, 120));
  if (noise > 0) {
    cv::Mat n(size, CV_16SC3);
    cv::RNG rng(seed);
    rng.fill(n, cv::RNG::NORMAL, 0.0, noise);
    cv::Mat wide;
    frame.convertTo(wide, CV_16SC3);
    wide += n;
    wide.convertTo(frame, CV_8UC3);  // saturating
  }
  return frame;
}

/// An antialiased filled disc centred at sub-pixel `centre` (pixel (0, 0) = centre
/// of the top-left pixel, as in geometry::Camera), 1/256 px resolution.
inline void drawDisc(cv::Mat& frame, cv::Point2d centre, double radius, const cv::Scalar& colour = kPaintedRed) {
  constexpr int shift = 8;
  const double scale = 1 << shift;
  cv::circle(frame, cv::Point(static_cast<int>(std::lround(centre.x * scale)), static_cast<int>(std::lround(centre.y * scale))),
             static_cast<int>(std::lround(radius * scale)), colour, cv::FILLED, cv::LINE_AA, shift);
}

/// A flat checkerboard on z = 0: inner_cols × inner_rows inner corners, squares of
/// `square` m, the first inner corner at the origin, x along the columns, y along the rows.
inline render::FrameDescription checkerboard(int inner_cols, int inner_rows, double square) {
  return render::checkerboardFrame({inner_cols, inner_rows, square});
}

/// The benchmark scene: 7,000 non-overlapping grey pebbles (radius 3–7 mm) in a
/// 0.5 × 0.16 × 0.3 m box on a floor, against a back wall and behind a Perspex wall
/// (the render benchmark's chute seen from the side); the 20 pebbles nearest the
/// Perspex (smallest y) are red markers, shifted by `shift` (m) along −x.
inline render::FrameDescription benchmarkScene(double shift = 0.0) {
  geometry::Rng rng(42);
  std::vector<double> radii(7000);
  for (double& r : radii) r = rng.uniform(0.003, 0.007);
  const auto centres = geometry::randomNonOverlapping(radii, Vec3(-0.25, -0.08, 0.0), Vec3(0.25, 0.08, 0.3), {}, rng);
  std::vector<std::size_t> order(centres.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::partial_sort(order.begin(), order.begin() + 20, order.end(),
                    [&](std::size_t a, std::size_t b) { return centres[a].y() - radii[a] < centres[b].y() - radii[b]; });
  render::FrameDescription f;
  for (std::size_t i = 0; i < centres.size(); ++i) f.spheres.push_back({centres[i], radii[i], render::kGreyPebble, Vec3::Zero()});
  for (int k = 0; k < 20; ++k) {
    render::SphereInstance& s = f.spheres[order[k]];
    s.colour = render::kRedMarker;
    s.centre.x() -= shift;
  }
  f.polygons.push_back({{{-0.4, -0.1, 0}, {0.4, -0.1, 0}, {0.4, 0.1, 0}, {-0.4, 0.1, 0}}, {0.4f, 0.38f, 0.35f}, 1.0f});
  f.polygons.push_back({{{-0.4, 0.09, 0}, {0.4, 0.09, 0}, {0.4, 0.09, 0.35}, {-0.4, 0.09, 0.35}}, {0.3f, 0.32f, 0.36f}, 1.0f});
  f.polygons.push_back({{{-0.4, -0.09, 0}, {0.4, -0.09, 0}, {0.4, -0.09, 0.35}, {-0.4, -0.09, 0.35}}, render::kPerspex, 0.15f});
  return f;
}

}  // namespace rocklab::track::test
