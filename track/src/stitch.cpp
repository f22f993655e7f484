#include "rocklab/track/stitch.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rocklab::track {

namespace {

[[noreturn]] void invalid(const std::string& field, const std::string& what, double got) {
  std::ostringstream s;
  s << "stitch." << field << ' ' << what << " (got " << got << ')';
  throw std::invalid_argument(s.str());
}

// Least-squares straight line through the last `n` points (pixel against time),
// evaluated at `time`; one point stands still.
cv::Point2d extrapolate(const Track& track, int n, double time) {
  const std::size_t count = std::min(track.points.size(), static_cast<std::size_t>(n));
  const auto first = track.points.end() - static_cast<std::ptrdiff_t>(count);
  double mt = 0;
  cv::Point2d mp(0, 0);
  for (auto p = first; p != track.points.end(); ++p) mt += p->time, mp += p->pixel;
  mt /= static_cast<double>(count);
  mp /= static_cast<double>(count);
  double stt = 0;
  cv::Point2d stp(0, 0);
  for (auto p = first; p != track.points.end(); ++p) {
    stt += (p->time - mt) * (p->time - mt);
    stp += (p->time - mt) * (p->pixel - mp);
  }
  const cv::Point2d velocity = stt > 0 ? stp / stt : cv::Point2d(0, 0);  // px/s
  return mp + velocity * (time - mt);
}

constexpr double kNone = std::numeric_limits<double>::infinity();

}  // namespace

void StitchSettings::validate() const {
  if (max_gap_frames < 0) invalid("max_gap_frames", "must be >= 0 frames", max_gap_frames);
  if (!(max_distance_px > 0.0) || !std::isfinite(max_distance_px))
    invalid("max_distance_px", "must be a finite distance > 0 px", max_distance_px);
  if (velocity_points < 2) invalid("velocity_points", "must be >= 2", velocity_points);
  if (!(ambiguity_ratio > 0.0 && ambiguity_ratio <= 1.0)) invalid("ambiguity_ratio", "must be in (0, 1]", ambiguity_ratio);
}

StitchResult stitchTracks(const std::vector<Track>& tracks, const StitchSettings& settings,
                          const std::vector<int>& ended_ambiguous) {
  settings.validate();
  const std::size_t n = tracks.size();
  auto endedAmbiguous = [&](const Track& t) {
    return std::find(ended_ambiguous.begin(), ended_ambiguous.end(), t.id) != ended_ambiguous.end();
  };
  // miss[a][b]: candidate A → B within both gates, else infinity. A track that
  // ended at an ambiguous match is a candidate like any other: the linker's 2-point
  // prediction was in doubt, the least-squares extrapolation here decides it, and
  // only through the same mutual-nearest and ratio tests.
  std::vector<double> miss(n * n, kNone);
  for (std::size_t a = 0; a < n; ++a) {
    const TrackPoint& end = tracks[a].points.back();
    for (std::size_t b = 0; b < n; ++b) {
      const TrackPoint& start = tracks[b].points.front();
      const int gap = start.frame - end.frame - 1;
      if (b == a || gap < 0 || gap > settings.max_gap_frames || settings.max_gap_frames == 0) continue;
      const double d = cv::norm(extrapolate(tracks[a], settings.velocity_points, start.time) - start.pixel);
      if (d <= settings.max_distance_px) miss[a * n + b] = d;
    }
  }
  // Nearest and runner-up along a row (A's successors) or a column (B's predecessors).
  struct Best {
    std::size_t index = 0;
    double first = kNone, second = kNone;
  };
  auto bestOf = [&](std::size_t fixed, bool row) {
    Best b;
    for (std::size_t k = 0; k < n; ++k) {
      const double d = row ? miss[fixed * n + k] : miss[k * n + fixed];
      if (d < b.first) b.second = b.first, b.first = d, b.index = k;
      else if (d < b.second) b.second = d;
    }
    return b;
  };
  auto clear = [&](const Best& b) { return b.first <= settings.ambiguity_ratio * b.second; };

  StitchResult out;
  std::vector<std::size_t> next(n, n);
  std::vector<char> has_previous(n, 0), candidate_after(n, 0), candidate_before(n, 0);
  for (std::size_t a = 0; a < n; ++a) {
    const Best successor = bestOf(a, true);
    if (!std::isfinite(successor.first)) continue;
    const std::size_t b = successor.index;
    candidate_after[a] = 1;
    for (std::size_t k = 0; k < n; ++k)
      if (std::isfinite(miss[a * n + k])) candidate_before[k] = 1;
    const Best predecessor = bestOf(b, false);
    if (predecessor.index != a || !clear(successor) || !clear(predecessor)) continue;
    next[a] = b;
    has_previous[b] = 1;
    out.joins.push_back({tracks[a].id, tracks[b].id, tracks[b].points.front().frame - tracks[a].points.back().frame - 1,
                         successor.first});
  }
  // Unresolved: a track that had a candidate on a side and was not joined there, or
  // that ended at an ambiguous match and was not continued.
  for (std::size_t k = 0; k < n; ++k)
    if ((candidate_after[k] && next[k] == n) || (candidate_before[k] && !has_previous[k]) ||
        (endedAmbiguous(tracks[k]) && next[k] == n))
      out.unresolved.push_back(tracks[k].id);
  for (std::size_t k = 0; k < n; ++k) {
    if (has_previous[k]) continue;  // part of a chain started earlier
    Track joined = tracks[k];
    for (std::size_t c = next[k]; c < n; c = next[c])
      joined.points.insert(joined.points.end(), tracks[c].points.begin(), tracks[c].points.end());
    out.tracks.push_back(std::move(joined));
  }
  std::sort(out.tracks.begin(), out.tracks.end(), [](const Track& x, const Track& y) { return x.id < y.id; });
  std::sort(out.unresolved.begin(), out.unresolved.end());
  return out;
}

}  // namespace rocklab::track
