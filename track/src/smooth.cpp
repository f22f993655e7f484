#include "rocklab/track/smooth.h"

#include <Eigen/Dense>

namespace rocklab::track {

void smoothTrack(Track& track, int half_window) {
  const std::vector<TrackPoint> original = track.points;
  const std::size_t n = original.size();
  std::size_t lo = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const int frame = original[i].frame;
    while (original[lo].frame < frame - half_window) ++lo;
    std::size_t hi = i;
    while (hi + 1 < n && original[hi + 1].frame <= frame + half_window) ++hi;
    if (hi - lo + 1 < 5) continue;
    // Normal equations of a + b τ + c τ², τ = t − t_i (ms, for conditioning); the
    // value at τ = 0 is a. One solve for every coordinate; a centre is smoothed only
    // when the whole window has one.
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Matrix<double, 3, 5> rhs = Eigen::Matrix<double, 3, 5>::Zero();
    bool centres = true;
    for (std::size_t j = lo; j <= hi; ++j) {
      const TrackPoint& p = original[j];
      const double tau = 1e3 * (p.time - original[i].time);
      const Eigen::Vector3d basis(1.0, tau, tau * tau);
      normal += basis * basis.transpose();
      centres = centres && p.centre.allFinite();
      Eigen::Matrix<double, 1, 5> values;
      values << p.pixel.x, p.pixel.y, p.centre.x(), p.centre.y(), p.centre.z();
      rhs += basis * values;
    }
    const Eigen::LDLT<Eigen::Matrix3d> solver(normal);
    if (solver.info() != Eigen::Success) continue;
    const Eigen::Matrix<double, 3, 5> coefficients = solver.solve(rhs);
    TrackPoint& out = track.points[i];
    out.pixel = {coefficients(0, 0), coefficients(0, 1)};
    if (centres) out.centre = {coefficients(0, 2), coefficients(0, 3), coefficients(0, 4)};
  }
}

}  // namespace rocklab::track
