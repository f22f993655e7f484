#pragma once
// Angle of repose of a static heap, measured the way the lab did: from the side.
//
// The heap is looked at along y (x–z view) and along x (y–z view). In each view
// the silhouette is the highest point of any ball's outline per bin of the
// horizontal axis u (measured from the heap axis, the mean (x, y) of the balls).
// Each view has two flanks, one on each side of its peak bin. A flank is fitted
// by least squares over the bins whose height lies between 20 % and 80 % of the
// peak height: below 20 % is the toe (single balls rolled out, the first layer),
// above 80 % the rounded top. The angle of a flank is atan(|slope|); the heap's
// angle is the mean of the four flanks, their (sample) standard deviation the
// measure of how round and symmetric the heap is.
#include <cstddef>
#include <string>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::experiments {

struct HeapAngle {
  double mean_deg = 0;            // mean of the flank angles (degrees)
  double std_deg = 0;             // their sample standard deviation (n − 1 = 3) (degrees)
  std::vector<double> flank_deg;  // the four flanks: -x, +x (x–z view), -y, +y (y–z view) (degrees)
  double height_m = 0;            // peak height above the base: max(z + r) − base_z (m)
  double base_radius_m = 0;       // mean horizontal distance from the axis where the fitted flanks reach the base (m)
  std::size_t balls = 0;          // number of balls analysed
  std::string method;             // one sentence describing the method, for results.json
};

/// Angle of repose of a heap of balls (clump members included) resting on a horizontal base at z = base_z.
/// Method (as the lab looked at the heap from the side): the heap axis is the mean (x, y) of the balls; for two
/// side views (project on x–z, then on y–z) the silhouette height h(u) is, for bins of width bin_width along the
/// horizontal axis u, the highest point of any ball's outline in that bin (z + sqrt(r² − (u − u_c)²) at the bin
/// centre, with r² − (u − u_c)² clamped at 0 for a ball that overlaps the bin but not its centre); each flank
/// (u < peak, u > peak) is fitted by least squares over the bins whose height is between 20 % and 80 % of the
/// view's peak height (excluding the rounded top and the toe); angle = atan(|slope|).
/// Throws std::invalid_argument when there are no balls, a ball is not finite, bin_width is not positive or the
/// balls span more than 10^7 bins, or when a flank is no slope: fewer than 3 bins in the band, a band narrower
/// than one mean ball diameter along u (the rounded edge of a flat layer), or a fitted line that does not rise
/// by the band's height (60 % of the peak) within the flank's width (band bins that are gaps between balls along
/// a flat top). A flat layer is thus an error, not 0°. Each message names the flank and what it lacks.
HeapAngle angleOfRepose(const std::vector<geometry::Sphere>& balls, double base_z, double bin_width);

}  // namespace rocklab::experiments
