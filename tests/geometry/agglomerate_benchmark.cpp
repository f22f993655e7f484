// Void filling of a 50 mm agglomerate (r_max = 2.5 mm) for r0 = 2, 3, 4 from the
// geometric stand-in for the servo-compacted pack (relaxedRandomPack): sphere count,
// porosity, coordination number, largest overlap, cells by outcome, and time.
// Usage: agglomerate_benchmark [pack_count (default 560)] [seed (default 1)]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <numbers>

#include "rocklab/geometry/agglomerate_packing.h"
#include "rocklab/geometry/random_pack.h"

using namespace rocklab::geometry;

int main(int argc, char** argv) {
  const std::size_t count = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 560;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  const double r_max = 2.5e-3, R = 25e-3, gap = 1e-3;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const RandomPackResult pack = relaxedRandomPack(count, r_max, R, seed);
  const double pack_s = std::chrono::duration<double>(Clock::now() - t0).count();
  const StructureStatistics loose =
      structureStatistics(pack.spheres, 4.0 / 3.0 * std::numbers::pi * R * R * R, gap);
  std::printf(
      "pack: %zu spheres r = 2.5 mm in R = 25 mm, %d sweeps, residual overlap %.3g m, porosity "
      "%.4f, "
      "CN %.2f, %.2f s\n",
      count, pack.sweeps, pack.max_overlap, loose.porosity, loose.coordination_number, pack_s);
  std::printf("%4s %8s %9s %6s %10s %7s %6s %6s %8s %8s %8s %8s %7s\n", "r0", "spheres", "porosity",
              "CN", "max_ovl", "passes", "tang", "grown", "tried", "small", "outside", "nofit",
              "time_s");
  for (double r0 : {2.0, 3.0, 4.0}) {
    VoidFillParams p;
    p.r_max = r_max;
    p.r0 = r0;
    p.agglomerate_radius = R;
    p.gap_tolerance = gap;
    p.seed = seed;
    const auto t1 = Clock::now();
    const VoidFillResult out = fillVoids(pack.spheres, p);
    const double s = std::chrono::duration<double>(Clock::now() - t1).count();
    const VoidFillReport& r = out.report;
    std::printf("%4.0f %8zu %9.4f %6.2f %10.2e %7d %6zu %6zu %8zu %8zu %8zu %8zu %7.2f\n", r0,
                r.structure.sphere_count, r.structure.porosity, r.structure.coordination_number,
                r.structure.max_overlap_fraction, r.passes, r.placed_tangent, r.placed_grown,
                r.cells_tried, r.rejected_too_small,
                r.rejected_centre_outside + r.rejected_outside_agglomerate, r.rejected_cannot_fit,
                s);
  }
  return 0;
}
