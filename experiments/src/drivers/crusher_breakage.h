#pragma once
// Population-balance breakage in the crusher run (experiments.md §g.6), the
// setting [experiment.breakage] of the `crusher` experiment (off without it):
// every check_interval each ball's octahedral shear stress q (from its contact
// stress, particle_stress.h) is compared with its strength (crusher/breakage_model.h,
// drawn from the scene seed and the ball's id); a ball of at least min_diameter
// whose q exceeds it is replaced by fragments inside it along its minor principal
// stress direction, which the freeze (crusher/breakage_freeze.h) eases apart before
// the run goes on. Fragments get new ids, their parent's velocity and spin, and a
// material of their size class (k = 4 R E_c at the class middle, Eq 6-14).
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "crusher/breakage_freeze.h"
#include "crusher/breakage_model.h"
#include "drivers/experiment.h"
#include "scene/toml_reader.h"

namespace rocklab::experiments {

struct BreakageSettings {
  bool enabled = false;        // the table [experiment.breakage] is there
  double check_interval = 0;   // s between checks; 0 = automatic (automaticCheckInterval)
  // When the checks begin (§g.4 [X]: "whether breakage checks start before the
  // mantle moves" is not stated). Feed: from t = 0, so the feed may break in the
  // feed bin on the stop wall (our first reading, kept as the default). Release:
  // from the stop wall's removal (crusher.release_time), when the feed falls into
  // the chamber; the bin is the procedure's way of making the feed, not part of
  // the machine. A weak feed (σ0 = 0.8 MPa at 28 mm) breaks 1,800 times in the bin
  // under "feed" (docs/crusher.md, the σ0 study).
  enum class Start { Feed, Release };
  Start start = Start::Feed;
  crusher::StrengthLaw strength;
  double min_diameter = 0.004;  // m, smaller balls never break (Table 6.2)
  crusher::SplitMode mode = crusher::SplitMode::Triple;
  std::vector<double> offsets;  // parent radii along the minor direction, one per fragment
  double youngs_modulus = 70e9;  // Pa, E_c of the fragments' k = 4 R E_c (Eq 6-14)
  double class_ratio = 1.25;     // fragment size classes: diameters min_diameter x ratio^i .. ^(i+1)
  crusher::FreezeSettings freeze;
  // A crowded freeze (its fragments found no room; the reference's freeze has no
  // such case) with freeze.crowded "break" and crowded_bound Overlap keeps the
  // breakage only while its largest overlap is at most this fraction of the smaller radius; above it the
  // parents are deferred as with "defer". The stall bound's reason
  // (breakage_freeze.h): handed back at k = 4 R E_c an overlap f R loads a ball to
  // q = 0.9 E_c f, 19 MPa at 3e-4, below the feed's strengths. Measured on the
  // three-ball nip with the cap cut to 2 contact times (docs/crusher.md, seventh
  // attempt): crowded freezes kept at 0.13-0.24 fired 97-251 J into a chamber whose
  // converged freezes add at most 2 uJ, and 17 balls were thrown out of it.
  double crowded_max_overlap = 3e-4;
  // What bounds a crowded breakage kept with "break" (docs/crusher.md, eighth attempt):
  //   Energy: the elastic energy the moved balls' contacts hold after the freeze at
  //     the run's law and stiffness (fragment-ball and fragment-wall; less what the
  //     moved neighbours' other contacts held before) may be at most
  //     crowded_energy_factor times what the parents' contacts (balls and walls)
  //     stored at the check that broke them: the breakage creates no elastic
  //     energy. (Kinetic energy is not created either: fragments take the
  //     parent's velocity and spin, whose rotational energy is smaller.)
  //   Overlap: the largest overlap at most crowded_max_overlap (the old rule).
  // Energy is the default from the 200-ball PBM run: it kept 11 crowded breakages
  // the overlap rule deferred, deferred 912 times against 1,469, did 36 M freeze
  // cycles against 56 M (5 % less wall time), and the mantle did 376 J of work
  // against 621 J, with the same product. Its cost: a parent the mantle squeezed while it waited gives
  // that back when it breaks (a kinetic jump of 1.18 J against 0.12 J).
  enum class CrowdedBound { Energy, Overlap };
  CrowdedBound crowded_bound = CrowdedBound::Energy;
  double crowded_energy_factor = 1.0;
  // s a deferred parent stays whole before it may break again; 0 = until the next
  // check. While it waits the closing mantle loads it, q = 0.9 k v t / d^2: where
  // the PBM chamber closes fastest (the closed side's bottom, whose gap swings by
  // +-6.6 mm at omega: v = 0.21 m/s) a ball of d = 8-28 mm at k = 4 R E_c gains
  // about its own strength q0(d) in 17-22 us. The 2 ms used until 2026-12-04 let it
  // gain up to ~100 strengths (the 200-ball run's mantle power swings). Until the
  // next check instead costs a crowded freeze at every check (every 0.35 us in the
  // 200-ball run) for as long as the pocket stays jammed.
  double defer_time = 2e-5;
};

/// Reads [experiment.breakage] (the `breakage` table of the experiment's table).
void readBreakageSettings(detail::TableReader& experiment_table, BreakageSettings& settings);
const char* crowdedBoundName(BreakageSettings::CrowdedBound bound);
const char* breakageStartName(BreakageSettings::Start start);

/// One ball that broke.
struct BreakageEvent {
  double time = 0;                   // s
  std::uint64_t parent = 0;          // id
  double diameter = 0;               // m
  double q = 0, strength = 0;        // Pa
  std::vector<std::uint64_t> fragments;  // ids
  // The freeze that followed (shared by the events of one check): its cycles, how
  // it ended and the largest fragment overlap it left (fraction of the smaller radius).
  std::uint64_t freeze_cycles = 0;
  crusher::FreezeEnd freeze_end = crusher::FreezeEnd::Converged;
  double freeze_overlap = 0;
  double freeze_contact_times = 0;  // its length in the heaviest mover's contact times (its cap's unit)
  // J, the largest rise of the run's kinetic energy within kJumpWindow contact
  // times of the heaviest fragment (rock stiffness) after the check, over its value
  // just before: what the fragments' handed-back overlaps fired (shared by the check's events).
  double kinetic_jump = 0;
  double mass = 0;  // kg, the parent's
  // J, shared by the check's events (BreakageSettings::CrowdedBound): the elastic
  // energy the parents' contacts stored at the check, and what the moved balls'
  // contacts hold after the freeze at the run's stiffness (net of the moved
  // neighbours' own contacts before).
  double parent_energy = 0, handed_back_energy = 0;
  std::vector<double> fragment_diameters, fragment_masses;  // m, kg; in the order of `fragments`
};

class CrusherBreakage {
 public:
  CrusherBreakage(BreakageSettings settings, std::uint64_t seed);
  /// Checks the run can break balls (linear law, a step stable for the smallest
  /// fragment) and sets the check interval; throws std::invalid_argument naming
  /// the keys otherwise.
  void start(const sim::World& world);
  /// Every check_interval: breaks the balls over their strength and rebuilds the
  /// world after the freeze. Returns whether the world changed.
  bool check(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx);

  /// The last check's freeze was cut short by a stop request: nothing changed.
  bool interrupted() const { return interrupted_; }
  const std::vector<BreakageEvent>& events() const { return events_; }
  /// For the progress line: the events and how the freezes so far ended (the
  /// report is written only at the end of a run).
  std::string progress() const;
  std::size_t fragmentsCreated() const { return fragments_created_; }
  /// Wall time (s) this run spent in the checks (stresses, strengths, splits and
  /// the World rebuilt after a breakage) and in the freezes: the breakage's cost
  /// beside the whole stepping. Not saved for a restart (like wall_time_s).
  double checkSeconds() const { return check_seconds_; }
  double freezeSeconds() const { return freeze_seconds_; }
  /// results.json's crusher.breakage (without the mass balance, which the driver
  /// adds) and breakage.csv.
  nlohmann::json report(const std::vector<double>& sieves_mm, const std::filesystem::path& out_dir) const;

  /// What a restart needs besides the settings and the seed (Experiment::saveState).
  nlohmann::json saveState() const;
  /// Puts back what saveState gave, and the fragment materials the run had added
  /// to `model` (the scene's), in their order. Throws std::invalid_argument (or
  /// nlohmann::json::exception) when the state does not fit the model.
  void restoreState(const nlohmann::json& state, sim::Model& model);

  /// The material a fragment of `diameter` broken from a ball of `material` gets:
  /// its size class's copy of the feed material (added to `model` when new).
  int fragmentMaterial(sim::Model& model, int material, double diameter);

  /// The default check interval: a quarter of the shortest contact time
  /// pi sqrt(m / k) a ball that can break has on a wall (a ball of min_diameter of
  /// each material in `p`, on the stiffer of its material's and its fragment
  /// class's spring), s.
  double automaticCheckInterval(const sim::Model& model, const sim::ParticleState& p) const;

 private:
  BreakageSettings s_;
  std::uint64_t seed_;
  double check_interval_ = 0;  // s, the one in use (set or automatic)
  std::uint64_t every_ = 1;
  std::uint64_t next_id_ = 0;
  std::map<int, int> base_of_;                    // fragment material -> the feed material it copies
  std::map<std::pair<int, int>, int> class_material_;  // (feed material, class) -> material
  std::vector<BreakageEvent> events_;
  /// check() once it is due: breaks the balls over their strength, freezes their
  /// fragments and rebuilds the world; whether it changed.
  bool breakOverStrength(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx);
  /// The copy of `feed` that fragments of `size_class` get (fragmentMaterial).
  sim::Material classMaterial(const sim::Material& feed, int feed_index, int size_class) const;
  /// Follows the run's kinetic energy after a check that broke balls (BreakageEvent::kinetic_jump).
  void watchKineticJump(const sim::World& world);
  struct JumpWatch {
    double before = 0;  // J, just before the check
    double until = 0;   // s
    std::size_t first_event = 0, end_event = 0;
    NLOHMANN_DEFINE_TYPE_INTRUSIVE(JumpWatch, before, until, first_event, end_event)
  };
  std::optional<JumpWatch> jump_watch_;
  struct Deferral {  // a crowded freeze: its time, parents, cycles and the overlap it left
    double time = 0;
    std::vector<std::uint64_t> parents;
    std::uint64_t cycles = 0;
    double overlap = 0;
    double parent_energy = 0, handed_back_energy = 0;  // J, as BreakageEvent's (0 with "defer")
    NLOHMANN_DEFINE_TYPE_INTRUSIVE(Deferral, time, parents, cycles, overlap, parent_energy, handed_back_energy)
  };
  std::vector<Deferral> deferrals_;
  std::map<std::uint64_t, double> deferred_until_;  // id -> time before which it does not break
  /// The strength of the ball in `row` (id, diameter), drawn once and kept for the
  /// checks that follow rather than two powers and a logarithm for every ball at
  /// every check; a row that now holds another ball is drawn again. Not saved: the
  /// draw depends on the seed and id alone.
  double strengthOf(std::uint32_t row, std::uint64_t id, double diameter);
  struct KeptStrength {
    std::uint64_t id = 0;
    double diameter = -1;  // m; no ball has it: the first look draws
    double strength = 0;   // Pa
  };
  std::vector<KeptStrength> kept_strengths_;
  std::size_t fragments_created_ = 0;
  bool interrupted_ = false;
  double check_seconds_ = 0, freeze_seconds_ = 0;

  /// What saveState writes and restoreState reads (but jump_watch_): each member
  /// once, as f(key, member), for a const or a mutable self.
  template <class Self, class F>
  static void savedFields(Self& self, F&& f) {
    f("check_interval", self.check_interval_);
    f("every", self.every_);
    f("next_id", self.next_id_);
    f("class_material", self.class_material_);
    f("events", self.events_);
    f("deferrals", self.deferrals_);
    f("deferred_until", self.deferred_until_);
    f("fragments_created", self.fragments_created_);
    f("freezes", self.freezes_);
    f("freeze_cycles", self.freeze_cycles_);
    f("max_freeze_cycles", self.max_freeze_cycles_);
    f("freezes_stalled", self.freezes_stalled_);
    f("freezes_crowded", self.freezes_crowded_);
    f("max_freeze_balls", self.max_freeze_balls_);
    f("reach_widenings", self.reach_widenings_);
    f("moved_neighbours", self.moved_neighbours_);
    f("max_freeze_overlap", self.max_freeze_overlap_);
    f("max_crowded_overlap", self.max_crowded_overlap_);
    f("max_crowded_handed_back", self.max_crowded_handed_back_);
    f("max_excess", self.max_excess_);  // -inf before the first kept freeze: CBOR keeps it
  }
  std::uint64_t freezes_ = 0, freeze_cycles_ = 0, max_freeze_cycles_ = 0;
  std::uint64_t freezes_stalled_ = 0, freezes_crowded_ = 0;  // crowded: kept with freeze_crowded "break"
  double max_freeze_overlap_ = 0;         // the largest overlap fraction a freeze left
  double max_crowded_overlap_ = 0;        // ...a crowded one whose breakage was kept
  double max_crowded_handed_back_ = 0;    // J, the most a kept crowded freeze handed back
  double max_excess_ = -std::numeric_limits<double>::infinity();  // J, handed back - parents' over kept freezes
  std::size_t max_freeze_balls_ = 0;      // the most balls a freeze World held
  std::uint64_t reach_widenings_ = 0;     // "local" freezes run again with a wider reach
  std::uint64_t moved_neighbours_ = 0;    // "local": loose neighbours the freezes moved
};

}  // namespace rocklab::experiments
