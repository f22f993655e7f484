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
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
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
  crusher::StrengthLaw strength;
  double min_diameter = 0.004;  // m, smaller balls never break (Table 6.2)
  crusher::SplitMode mode = crusher::SplitMode::Triple;
  std::vector<double> offsets;  // parent radii along the minor direction, one per fragment
  double youngs_modulus = 70e9;  // Pa, E_c of the fragments' k = 4 R E_c (Eq 6-14)
  double class_ratio = 1.25;     // fragment size classes: diameters min_diameter x ratio^i .. ^(i+1)
  crusher::FreezeSettings freeze;
  // s a ball whose fragments found no room (a "crowded" freeze) stays whole before
  // it may break again; a choice of ours, the reference's freeze has no such case.
  double defer_time = 2e-3;
};

/// Reads [experiment.breakage] (the `breakage` table of the experiment's table).
void readBreakageSettings(detail::TableReader& experiment_table, BreakageSettings& settings);

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
  double mass = 0;  // kg, the parent's
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

  const std::vector<BreakageEvent>& events() const { return events_; }
  /// For the progress line: the events and how the freezes so far ended (the
  /// report is written only at the end of a run).
  std::string progress() const;
  std::size_t fragmentsCreated() const { return fragments_created_; }
  /// results.json's crusher.breakage (without the mass balance, which the driver
  /// adds) and breakage.csv.
  nlohmann::json report(const std::vector<double>& sieves_mm, const std::filesystem::path& out_dir) const;

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
  struct Deferral {  // a crowded freeze: its time, parents, cycles and the overlap it left
    double time = 0;
    std::vector<std::uint64_t> parents;
    std::uint64_t cycles = 0;
    double overlap = 0;
  };
  std::vector<Deferral> deferrals_;
  std::map<std::uint64_t, double> deferred_until_;  // id -> time before which it does not break
  std::size_t fragments_created_ = 0;
  std::uint64_t freezes_ = 0, freeze_cycles_ = 0, max_freeze_cycles_ = 0;
  std::uint64_t freezes_stalled_ = 0;
  double max_freeze_overlap_ = 0;         // the largest overlap fraction a freeze left
  std::size_t max_freeze_balls_ = 0;      // the most balls a freeze World held
  std::uint64_t reach_widenings_ = 0;     // "local" freezes run again with a wider reach
  std::uint64_t moved_neighbours_ = 0;    // "local": loose neighbours the freezes moved
};

}  // namespace rocklab::experiments
