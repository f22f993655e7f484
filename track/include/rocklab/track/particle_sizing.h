#pragma once
// Particle sizes from a photograph, as plants size a product on a belt or a tray:
// a calibrated camera looks down on the particles lying on a flat surface of a
// contrasting colour. Only the image and the camera are used (never the truth).
//
//   1. foreground: the surface's own shading (a lit belt is brighter under the
//      lamp) taken away by a white top-hat (the grey image minus its opening with
//      a square window wider than any particle), then pixels above a threshold
//      (Otsu's when none is given), opened by one pixel;
//   2. touching particles: each connected component's distance-transform peaks are
//      the particle centres (a peak inside the inscribed circle of a higher one is
//      dropped: one particle, one peak); every pixel goes to the centre k that
//      minimises |x − c_k| − ρ_k (ρ_k the peak's distance value): for two touching
//      discs this border runs through their point of contact;
//   3. size: the pixels of a particle taken onto the surface plane raised by half
//      the particle's own size (its outline lies about half way up a particle
//      lying on the surface; iterated from the surface plane), giving
//        equivalent diameter  d_A = √(4A/π) (A: projected area, m²),
//        Feret diameters      largest and smallest caliper width of the outline
//                             (convex hull of the pixels' corners, m).
//
// What it cannot see, it does not report: a particle hidden under others is not
// found, two that the peaks do not separate are one, and a particle cut by the
// image border is flagged (`on_border`).
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/vec.h"

namespace rocklab::track {

struct SizingSettings {
  double threshold = -1.0;      // grey level (0-255) above the surface at which a pixel is a particle; < 0: Otsu's
  bool flatten_background = true;  // the top-hat of step 1
  int background_window_px = 0;    // its window [px], wider than the largest particle; 0: a quarter of the shorter image side
  double min_peak_px = 2.0;     // a centre is at least this far from the background [px]
  double min_area_px = 12.0;    // smaller pieces are noise
  int outline_iterations = 3;   // half-size plane updates (0: the surface plane itself)

  /// Throws std::invalid_argument naming the first invalid field ("sizing.min_peak_px ...").
  void validate() const;
};

struct SizedParticle {
  int label = 0;                         // in SizingResult::labels (1, 2, ...)
  cv::Point2d centre_px;                 // the distance-transform peak
  double area_px = 0.0;
  double area_m2 = 0.0;                  // projected area on its plane
  double equivalent_diameter_m = 0.0;    // √(4A/π)
  double feret_max_m = 0.0, feret_min_m = 0.0;
  double outline_height_m = 0.0;         // height of the plane it was sized on, above the surface
  bool on_border = false;                // touches the image border: cut, its size is a lower bound
};

struct SizingResult {
  std::vector<SizedParticle> particles;
  cv::Mat labels;         // CV_32S, 0 = background, else SizedParticle::label
  double threshold = 0;   // grey level used
};

/// `surface_point`, `surface_normal`: the surface the particles lie on (world frame;
/// the normal points towards the camera side, any length > 0). Throws
/// std::invalid_argument for an empty or non-BGR image or bad settings.
SizingResult sizeParticles(const cv::Mat& bgr, const geometry::Camera& camera, const geometry::Vec3& surface_point,
                           const geometry::Vec3& surface_normal, const SizingSettings& settings = {});

}  // namespace rocklab::track
