// Hungarian assignment against brute force; the Linker keeps identities where a
// greedy linker swaps them; empty frames and missed frames.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <cstdio>
#include <numeric>
#include <random>

#include "rocklab/track/assignment.h"
#include "rocklab/track/link.h"

using namespace rocklab::track;

namespace {

Detection at(double u, double v) {
  Detection d;
  d.centroid = {u, v};
  d.area_px = 50;
  d.radius_px = 4;
  d.fill = 0.9;
  return d;
}

double total(const std::vector<double>& cost, int cols, const std::vector<int>& rowToCol) {
  double sum = 0;
  for (std::size_t i = 0; i < rowToCol.size(); ++i)
    if (rowToCol[i] >= 0) sum += cost[i * cols + rowToCol[i]];
  return sum;
}

// The least total over all assignments of min(rows, cols) pairs, by enumeration.
double bruteForce(const std::vector<double>& cost, int rows, int cols) {
  const bool wide = rows <= cols;
  const int small = wide ? rows : cols, large = wide ? cols : rows;
  std::vector<int> perm(large);
  std::iota(perm.begin(), perm.end(), 0);
  double best = 1e300;
  do {
    double sum = 0;
    for (int k = 0; k < small; ++k) sum += wide ? cost[k * cols + perm[k]] : cost[perm[k] * cols + k];
    best = std::min(best, sum);
  } while (std::next_permutation(perm.begin(), perm.end()));
  return best;
}

}  // namespace

TEST_CASE("the Hungarian algorithm finds the least total cost", "[track][link]") {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> uniform(0.0, 10.0);
  int checked = 0;
  for (int rows = 1; rows <= 6; ++rows)
    for (int cols = 1; cols <= 6; ++cols)
      for (int trial = 0; trial < 5; ++trial) {
        std::vector<double> cost(rows * cols);
        for (double& c : cost) c = trial == 4 ? std::round(uniform(rng) / 3) : uniform(rng);  // trial 4: many ties
        const std::vector<int> rowToCol = solveAssignment(cost, rows, cols);
        // Each column at most once, min(rows, cols) pairs.
        std::vector<int> used;
        for (int c : rowToCol)
          if (c >= 0) used.push_back(c);
        std::sort(used.begin(), used.end());
        CHECK(std::adjacent_find(used.begin(), used.end()) == used.end());
        CHECK(static_cast<int>(used.size()) == std::min(rows, cols));
        CHECK(total(cost, cols, rowToCol) == Approx(bruteForce(cost, rows, cols)).margin(1e-12));
        ++checked;
      }
  CHECK(checked == 180);
}

TEST_CASE("two markers competing for one prediction keep their ids where greedy swaps them", "[track][link]") {
  // Markers A (v = 0) and B (v = 8 px) move right at 3 px/frame. At frame 6 A stops
  // (3 px short of its prediction) and B swerves 5.5 px towards A: B's detection is
  // then nearer A's prediction (2.5 px) than A's own (3 px). Greedy takes that
  // nearest pair first, B finds nothing inside the 6 px gate, and A's detection
  // starts a new track: both identities are broken. The optimal assignment
  // (9 + 30.25 px² against 6.25 + 2 · 36 px² of misses) keeps both.
  std::vector<cv::Point2d> a, b;
  for (int k = 0; k <= 5; ++k) a.emplace_back(3.0 * k, 0.0), b.emplace_back(3.0 * k, 8.0);
  a.emplace_back(15.0, 0.0), b.emplace_back(18.0, 2.5);  // frame 6
  for (int k = 7; k <= 12; ++k) a.emplace_back(15.0 + 3.0 * (k - 6), 0.0), b.emplace_back(18.0 + 3.0 * (k - 6), 2.5);
  // The premise: greedy and optimal differ on frame 6.
  const cv::Point2d predictedA(18.0, 0.0), predictedB(18.0, 8.0);
  CHECK(cv::norm(b[6] - predictedA) < cv::norm(a[6] - predictedA));
  CHECK(cv::norm(b[6] - predictedA) < cv::norm(b[6] - predictedB));
  CHECK(cv::norm(a[6] - predictedB) > 6.0);

  auto run = [&](LinkSettings::Assignment method) {
    LinkSettings settings;
    settings.max_distance_px = 6.0;
    settings.assignment = method;
    Linker linker(settings);
    for (std::size_t k = 0; k < a.size(); ++k)
      linker.add(static_cast<int>(k), k / 500.0, k % 2 ? std::vector<Detection>{at(a[k].x, a[k].y), at(b[k].x, b[k].y)}
                                                         : std::vector<Detection>{at(b[k].x, b[k].y), at(a[k].x, a[k].y)});
    return linker.tracks();
  };
  auto follows = [](const Track& t, const std::vector<cv::Point2d>& truth) {
    if (t.points.size() != truth.size()) return false;
    for (std::size_t k = 0; k < truth.size(); ++k)
      if (t.points[k].frame != static_cast<int>(k) || cv::norm(t.points[k].pixel - truth[k]) > 1e-12) return false;
    return true;
  };

  const std::vector<Track> optimal = run(LinkSettings::Assignment::Hungarian);
  REQUIRE(optimal.size() == 2);
  const bool aFirst = optimal[0].points[0].pixel.y == 0.0;  // frame 0 lists B first
  CHECK(follows(optimal[aFirst ? 0 : 1], a));
  CHECK(follows(optimal[aFirst ? 1 : 0], b));

  const std::vector<Track> greedy = run(LinkSettings::Assignment::Greedy);
  CHECK(greedy.size() > 2);  // identities broken: the case discriminates
  std::printf("competing markers: Hungarian %zu tracks (ids kept), greedy %zu tracks (ids swapped/broken)\n",
              optimal.size(), greedy.size());
}

TEST_CASE("the linker tolerates empty frames and re-finds a marker after missed frames", "[track][link]") {
  LinkSettings settings;
  settings.max_distance_px = 5.0;
  settings.max_missed_frames = 2;
  Linker linker(settings);
  linker.add(0, 0.000, {});  // nothing yet
  // A marker at 4 px/frame, unseen in frames 4 and 5 (two misses), then seen again.
  for (int k = 1; k <= 10; ++k) linker.add(k, k * 0.002, k == 4 || k == 5 ? std::vector<Detection>{} : std::vector<Detection>{at(4.0 * k, 10.0)});
  std::vector<Track> tracks = linker.tracks();
  REQUIRE(tracks.size() == 1);
  CHECK(tracks[0].points.size() == 8);
  CHECK(tracks[0].points[3].frame == 6);  // re-found: the prediction spans the gap

  // Three misses retire it: the marker returns as a new track.
  for (int k = 11; k <= 13; ++k) linker.add(k, k * 0.002, {});
  linker.add(14, 14 * 0.002, {at(56.0, 10.0)});
  tracks = linker.tracks();
  REQUIRE(tracks.size() == 2);
  CHECK(tracks[1].points.size() == 1);
  CHECK(tracks[1].id == 1);

  CHECK_THROWS_WITH(linker.add(14, 0.1, {}), Catch::Contains("must increase"));
  LinkSettings bad;
  bad.max_distance_px = 0;
  CHECK_THROWS_WITH(Linker(bad), Catch::Contains("link.max_distance_px"));
}

TEST_CASE("a refined point keeps the linker on the centroids, a withdrawn track ends and an empty one is gone",
          "[track][link]") {
  Linker linker;
  linker.add(0, 0.000, {at(10, 10), at(60, 10)});
  REQUIRE(linker.lastTrackIds() == std::vector<int>{0, 1});
  // The shape fit moves track 0's reported point; the linker still predicts from the centroid.
  linker.refineLastPoint(0, {11.5, 10.0}, {0.1, 0.2, 0.3});
  linker.add(1, 0.002, {at(12, 10), at(62, 10)});
  CHECK(linker.lastTrackIds() == std::vector<int>{0, 1});
  const std::vector<Track> both = linker.tracks();
  CHECK(both[0].points[0].pixel == cv::Point2d(11.5, 10.0));
  CHECK(both[0].points[0].detected == cv::Point2d(10, 10));
  CHECK(both[0].points[0].centre.x() == 0.1);
  CHECK(std::isnan(both[0].points[1].centre.x()));
  // Track 1 withdraws in frame 1: its frame-1 point goes and it is no longer extended.
  linker.withdraw(1);
  CHECK_THROWS_AS(linker.withdraw(1), std::invalid_argument);
  linker.add(2, 0.004, {at(14, 10), at(64, 10)});
  const std::vector<Track> after = linker.tracks();
  REQUIRE(after.size() == 3);
  CHECK(after[1].points.size() == 1);  // frame 0 only
  CHECK(after[2].points.front().frame == 2);
  // A track withdrawn in its only frame has no point left and is left out.
  linker.withdraw(2);
  CHECK(linker.tracks().size() == 2);
}
