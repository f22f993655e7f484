#pragma once
// The "freeze" after breakage events (experiments.md §g.6 steps 1-8): the new
// fragments overlap each other (they were placed inside their parent) and their
// neighbours; released at the rock's stiffness that overlap would fire them apart
// and break them again. The freeze eases them apart in a World of its own:
//
//   - everything at rest (the run's velocities stay in the caller's state: step 1,
//     and step 8 gives them back untouched);
//   - walls held where they are at the breakage time (each wall's pose at t baked
//     into its geometry, no motion): the freeze World has its own clock, so the
//     run's simulated time does not advance and the mantle does not move;
//   - every ball's mass from the huge density (3e9 kg/m^3), the fragments'
//     stiffness (kn = ks) 1e3 N/m, no dashpots, local damping 0.9, no gravity;
//   - its own step: the automatic step of that model (the freeze's masses and
//     stiffnesses), not the run's;
//   - cycled until (a) no fragment overlaps a ball by more than overlap_fraction of
//     the smaller radius, nor a wall by more than that fraction of its own (a
//     fragment pressed into a held wall comes back at the wall's stiffness and
//     breaks again: until 2026-12-04 walls were not looked at), and (b) the kinetic energy is below kinetic_fraction of the
//     artificial energy the fragments' overlaps stored at the start (at the freeze
//     stiffness) [X]: pushed apart, that energy dissipated ("converged"). Fragments
//     that separate into free space coast (local damping stops accelerating motion
//     only): under the local damping alpha they leave with about (1 - alpha) = 10 %
//     of it, so the default 0.2 ends the freeze there rather than never;
//   - or ("stalled") (b) holds and the largest overlap has stopped falling: over the
//     last stall_window time scales it never went below (1 - stall_tolerance) of its
//     value at the window's start. Fragments pinched between the held walls (or heavy
//     neighbours) have no room to separate: their overlap settles where the soft
//     springs balance, above overlap_fraction, and (a) is never met. The freeze
//     then ends with what the walls and neighbours allow, the overlap reported,
//     provided that is at most stall_max_overlap: a plateau higher up is not the
//     walls' doing but a squeeze the fragments leave later (the small middle
//     fragment of a triple split held on the line between the other two, which
//     it leaves sideways only when a slow instability grows: in the 200-ball run
//     the largest overlap did not fall below 0.34 for longer than the window, was
//     0.005 after 200,000 cycles and met the criterion (a) after 206,000), and
//     handed back at rock stiffness it would fire the fragments apart. The bound (3e-4;
//     0.01 until 2026-12-04) is what a ball can take: an overlap f R at k = 4 R E_c
//     loads it to q = 0.9 k f R / d^2 = 0.9 E_c f, 19 MPa at 3e-4, below the weakest
//     strengths of the feed (q0 25 MPa at 21 mm). At 0.01 (630 MPa) every stall
//     handed back a contact that broke a ball at the next check: in a 200-ball run
//     10 of the 11 fragments of stalled freezes that broke again did so then.
//     The window is in the heaviest fragment's own time scale sqrt(m/k) (freeze mass
//     and stiffness), not in cycles: the freeze's step is set by the unbroken balls
//     (rock stiffness at the huge density), so a fixed number of cycles is a tiny or
//     a long time for the fragments depending on who is in the World. From rest
//     under local damping a fragment gains only (1 - alpha) of its force, so its
//     overlap falls as 1 - cos(sqrt(1 - alpha) t / sqrt(m/k)) of the way: 5 % of it
//     in one time scale, 19 % in the default 2. A window much shorter than that
//     would call a freeze that has barely started "stalled";
//   - more than its cap ("crowded"): the fragments have found no room. The cap is
//     max_contact_times contact times pi sqrt(m/k) of the heaviest mover (freeze
//     mass and stiffness), in cycles of the freeze's step, and never more than
//     max_cycles. In cycles alone a cap means nothing to the fragments: the old
//     1e6, sized for the "all" step (one time scale 7,000-14,000 cycles), is
//     some 10^4 contact times at the local freeze's own step, and each crowded
//     local freeze of the 200-ball run ran all of them (257 of its 261 million
//     freeze cycles). From rest under local damping alpha a free pair gains only
//     (1 - alpha) of its force and has parted after about (pi/2)/sqrt(1 - alpha)
//     = 5 time scales, 1.6 contact times; the slowest freeze that ended in the
//     200-ball runs (the triple split's middle fragment leaving the line
//     sideways, 206,000 cycles of the "all" step) took about 5-10 (15-30 time
//     scales of 7,000-14,000 cycles, estimated). The default 100 is ten times
//     that: a freeze that has not parted by then is jammed, not slow. (Measured
//     since: on the nip every freeze parted in 1.3-6.9; in the 200-ball run the
//     median was 7.4, 99 % within 86, 10 of 803 above 80: the slowest that part
//     in the full chamber reach the cap, docs/crusher.md, seventh attempt.)
//     A freeze is also crowded sooner ("jammed", jam_contact_times, off by
//     default) when it is at rest, above the stall bound, and its largest overlap
//     has not fallen by stall_tolerance over the last jam_contact_times contact
//     times: fragments pinched among held neighbours settle where the soft springs
//     balance and wait there for the cap (35 of the 36 million freeze cycles of the
//     200-ball run were such freezes). The window must be longer than the slowest
//     escape seen (the triple split's middle fragment leaving the line sideways
//     after a plateau of 5-10 contact times, above).
//     What follows is `crowded` (CrowdedOutcome): "break" hands the fragments
//     back where the freeze left them (the caller bounds what it takes, by energy
//     or overlap: crusher_breakage.h); "defer" leaves `state` as it was, and the caller keeps
//     the parents whole for a while; "stop" stops the run with a message naming
//     the settings. (In the 200-ball run two freezes after 1 s were still at
//     overlaps of 0.12-0.15 of the radius after 1e6 and 4e6 cycles, creeping down
//     by less than the stall rule's tolerance: fragments in a jammed pocket of
//     heavy neighbours.)
//
//   - a stop request (rocklab::experiments::stopRequested) is looked at with the
//     criteria: the freeze ends "interrupted" and leaves `state` as it was.
//
// Who takes part (scope):
//   - "all" (the reference's wording, step 3): every ball of the run, at the huge
//     density. The freeze's step is then set by the unbroken balls' rock stiffness
//     at that density, a few hundredths of the fragments' own time scale, so a
//     freeze costs hundreds of thousands of cycles over every ball of the chamber;
//   - "local" (the default, our reading of its intent): the fragments and the balls
//     within local_reach largest-fragment diameters of them (surface to surface).
//     Those neighbours are held: their density is held_density (1e30: a collision
//     cannot move them by a round-off), so the step is the fragments' own and the
//     freeze runs on a few dozen balls. Step 3 gives the unbroken balls a huge
//     density "so collisions barely move them": held, they do not move at all,
//     and the balls beyond the reach, which the fragments cannot touch, are left
//     out. Should a fragment end touching a ball outside the set (it travelled
//     further than the reach), the reach doubles and the freeze runs again from
//     the start. Neighbours that bore no load at the breakage (they touched
//     nothing but the parents: loose balls rattling in the chamber) are not held
//     but move like fragments (soft, at the freeze density), so the fragments can
//     push them aside as they would with every ball in; held, they would pin the
//     fragments. Only the movers' positions and contact history come back; the
//     held balls keep their own. A state with clumps is frozen whole ("all").
//
// Only the positions (and the contact history at them) come back; masses,
// stiffnesses, damping, gravity, wall motion and velocities are the run's again.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "rocklab/sim/world.h"

namespace rocklab::experiments::crusher {

/// Who takes part in the freeze (see the head of this file).
enum class FreezeScope { Local, All };
const char* freezeScopeName(FreezeScope scope);

/// What a crowded freeze leads to (see the head of this file).
enum class CrowdedOutcome { Break, Defer, Stop };
const char* crowdedOutcomeName(CrowdedOutcome outcome);

struct FreezeSettings {
  FreezeScope scope = FreezeScope::Local;
  double density = 3e9;           // kg/m^3, every ball's during the freeze ("local": the movers')
  double held_density = 1e30;     // kg/m^3, the held neighbours' ("local" only)
  double local_reach = 1.0;       // largest-fragment diameters, surface to surface ("local" only)
  double stiffness = 1e3;         // N/m, the fragments' kn and ks during the freeze
  double local_damping = 0.9;     // alpha
  double overlap_fraction = 1e-4; // largest fragment overlap / smaller radius that ends it
  double kinetic_fraction = 0.2;  // kinetic energy / the fragments' initial artificial energy that ends it
  double stall_tolerance = 0.01;   // relative fall of the largest overlap below which it has stalled
  double stall_window = 2.0;       // over this many of the heaviest fragment's sqrt(m/k); 0 = no stall rule
  double stall_max_overlap = 3e-4; // a stall ends the freeze only with the largest overlap at most this
  double max_contact_times = 100;  // crowded after this many of the heaviest mover's pi sqrt(m/k); 0 = max_cycles only
  double jam_contact_times = 0;    // crowded sooner when at rest with the largest overlap not falling for this many; 0 = off
  std::int64_t max_cycles = 1000000;  // ...and never after more cycles than this
  CrowdedOutcome crowded = CrowdedOutcome::Break;  // at the cap: end "crowded" (break, defer) or stop the run
  std::int64_t check_cycles = 20;  // cycles between looks at the criterion (at most a quarter of the stall window)
};

/// How a freeze ended: both criteria met, the kinetic one with the overlap
/// stalled, its cap passed (crowded "break" or "defer"), or a stop request
/// (Ctrl-C, SIGTERM) before either. After a crowded "defer" freeze and an
/// interrupted one `state` is the one from before the breakage.
enum class FreezeEnd { Converged, Stalled, Crowded, Interrupted };
const char* freezeEndName(FreezeEnd end);

struct FreezeResult {
  FreezeEnd end = FreezeEnd::Converged;
  std::uint64_t cycles = 0;        // over every run of it ("local": widened reaches included)
  double dt = 0.0;                 // s, the freeze's own step
  std::uint64_t stall_window_cycles = 0;  // the stall rule's window in cycles (0: off)
  double contact_time = 0.0;       // s, pi sqrt(m/k) of the heaviest mover at the freeze's mass and stiffness
  std::uint64_t cap_cycles = 0;    // the crowded cap in cycles: max_contact_times of those, at most max_cycles
  std::uint64_t jam_window_cycles = 0;  // the jam rule's window in cycles (0: off)
  bool jammed = false;             // crowded by the jam rule, before the cap
  double artificial_energy = 0.0;  // J, the fragments' overlaps at the freeze stiffness at the start
  double max_overlap = 0.0;        // largest fragment overlap / smaller radius (walls: / its radius) at the end
  double kinetic_energy = 0.0;     // J, at the end (freeze masses; "local": the movers')
  std::size_t balls = 0;           // balls in the freeze World (the last run of it)
  int reach_widenings = 0;         // "local": runs repeated with the reach doubled
  std::size_t moved_neighbours = 0;  // "local": neighbours that moved with the fragments (not loaded)
  // Rows of `state` whose positions the freeze moved: the fragments and the moved
  // neighbours ("local"), every ball ("all"); empty when nothing came back.
  std::vector<std::uint32_t> movers;
};

/// Relaxes the balls `fragments` (rows of state.particles) of `state` at time
/// state.time under `model` (the run's); on return state's positions and contact
/// history are those after the freeze (with scope "local" the fragments' only),
/// everything else as it was (a crowded freeze: only with crowded "break").
/// Throws std::runtime_error (the settings named) when the cap passes before
/// either way out and crowded is "stop".
/// `loaded` (scope "local"; one flag per ball of `state`, or empty): the balls that
/// bear load, touching a ball other than the broken parents or a wall at the
/// breakage (sim::World::touchingContacts). A neighbour not loaded moves in the
/// freeze like a fragment (soft, at `density`, in the criteria, its position
/// back); empty: every neighbour is held.
FreezeResult freezeFragments(const sim::Model& model, sim::WorldState& state,
                             const std::vector<std::uint32_t>& fragments, const FreezeSettings& settings,
                             int threads, const std::vector<bool>& loaded = {});

/// Kinetic energy of the balls `rows` (J): translation and rotation.
double kineticEnergy(const sim::ParticleState& p, const std::vector<std::uint32_t>& rows);

/// The largest overlap of any of `fragments` with any ball, over the smaller radius
/// of the pair, and the energy their overlaps store at the stiffnesses of `model`
/// (linear springs in series; walls are not counted: the freeze holds them).
struct FragmentOverlaps {
  double max_fraction = 0.0;
  double energy = 0.0;  // J
};
FragmentOverlaps fragmentOverlaps(const sim::Model& model, const sim::ParticleState& p,
                                  const std::vector<std::uint32_t>& fragments);

/// The balls of a state sorted into the cells of a box grid, each cell at least one
/// largest diameter wide, so that every ball touching a point's ball lies in the 27
/// cells around it: a counting sort into buffers that a kept object reuses, no
/// hashing (geometry::SphereHashGrid allocated a list per cell at every look of the
/// freeze's criteria). fragmentOverlaps and LargestOverlap find the balls near a
/// fragment through it.
class BallCells {
 public:
  /// Sorts the balls of `p`; false (and no cells) when a position is not finite.
  bool build(const sim::ParticleState& p);
  /// Calls visit(j) for every ball j in the 27 cells around x (x among the balls'
  /// box), cells in z, y, x order and balls in ball order within a cell.
  template <class Visit>
  void forEachNear(const geometry::Vec3& x, Visit&& visit) const {
    if (by_cell_.empty()) return;
    const std::array<std::size_t, 3> c = cellOf(x);
    for (std::size_t z = c[2] > 0 ? c[2] - 1 : 0; z <= std::min(c[2] + 1, dims_[2] - 1); ++z)
      for (std::size_t y = c[1] > 0 ? c[1] - 1 : 0; y <= std::min(c[1] + 1, dims_[1] - 1); ++y)
        for (std::size_t cx = c[0] > 0 ? c[0] - 1 : 0; cx <= std::min(c[0] + 1, dims_[0] - 1); ++cx) {
          const std::size_t k = index(cx, y, z);
          for (std::size_t m = first_[k]; m < first_[k + 1]; ++m) visit(by_cell_[m]);
        }
  }

 private:
  std::array<std::size_t, 3> cellOf(const geometry::Vec3& x) const {
    return {static_cast<std::size_t>((x[0] - lo_[0]) / cell_), static_cast<std::size_t>((x[1] - lo_[1]) / cell_),
            static_cast<std::size_t>((x[2] - lo_[2]) / cell_)};
  }
  std::size_t index(std::size_t cx, std::size_t cy, std::size_t cz) const {
    return (cz * dims_[1] + cy) * dims_[0] + cx;
  }
  geometry::Vec3 lo_ = geometry::Vec3::Zero(), hi_ = geometry::Vec3::Zero();
  double cell_ = 1.0;
  std::array<std::size_t, 3> dims_{1, 1, 1};
  std::vector<std::size_t> cell_of_, first_, fill_;
  std::vector<std::uint32_t> by_cell_;
};

/// The largest overlap of any of `movers` with any ball, over the smaller radius of
/// the pair: fragmentOverlaps' max_fraction to the bit, which the freeze's criteria
/// read every few cycles (building a hash grid there took a sixth of a freeze). A
/// largest value does not depend on the order in which the pairs come, so it needs
/// no sort; the cells are kept from one look to the next. (A sweep along x, tried
/// first, met every ball of a feed pile in the bin: half a freeze's time at sigma0
/// = 0.8 MPa.)
class LargestOverlap {
 public:
  double operator()(const sim::ParticleState& p, const std::vector<std::uint32_t>& movers);

 private:
  BallCells cells_;
};

}  // namespace rocklab::experiments::crusher
