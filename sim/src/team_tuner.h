#pragma once
// Chooses, between steps, whether the engine runs on its full thread team or on
// one thread, by timing both. Internal to rocklab_sim.
//
// Why: the results are bitwise the same on any team (forces.cpp), so the team
// only decides the wall time, and which team is faster is not known in advance.
// When another process holds a core (a shared node, a laptop, a second run
// beside this one), a team of two time-slices with it and waits at every
// barrier: the 16,000-ball settle scene ran 1.2x slower on two threads than on
// one beside a busy process, even with the short spin of app/main.cpp. So the
// tuner measures: a window on the current team, then a window on the other, and
// keeps the faster. A probe that confirms the current team doubles
// the time to the next probe (up to kMaxInterval), so a quiet machine pays a
// probe window about every half minute; a switch goes back to probing often.
#include <algorithm>
#include <cstdint>

namespace rocklab::sim::detail {

class TeamTuner {
 public:
  static constexpr double kWindow = 0.1;         // s of stepping per measured window
  static constexpr std::uint64_t kMinSteps = 20;  // ...and at least this many steps
  static constexpr double kFirstInterval = 2.0;   // s on the chosen team before the next probe
  static constexpr double kMaxInterval = 32.0;    // s, the longest gap between probes
  static constexpr double kMargin = 0.03;         // the other team must be this much faster

  /// Whether the next step runs on one thread (else on the full team).
  bool single() const { return phase_ == Phase::Probe ? !chosen_single_ : chosen_single_; }

  /// Accounts one step of `seconds` wall time (engine stages only). Returns true
  /// when the team of the next step differs from this one's.
  bool stepDone(double seconds) {
    const bool before = single();
    elapsed_ += seconds;
    ++steps_;
    switch (phase_) {
      case Phase::Measure:
        if (windowDone()) {
          current_per_step_ = elapsed_ / static_cast<double>(steps_);
          start(Phase::Probe);
        }
        break;
      case Phase::Probe:
        if (windowDone()) {
          const double other = elapsed_ / static_cast<double>(steps_);
          if (other < (1.0 - kMargin) * current_per_step_) {
            chosen_single_ = !chosen_single_;
            ++switches_;
            interval_ = kFirstInterval;
          } else {
            interval_ = std::min(2.0 * interval_, kMaxInterval);
          }
          ++probes_;
          start(Phase::Settled);
        }
        break;
      case Phase::Settled:
        if (elapsed_ >= interval_) start(Phase::Measure);
        break;
    }
    if (before) ++single_steps_;
    return single() != before;
  }

  std::uint64_t probes() const { return probes_; }
  std::uint64_t switches() const { return switches_; }
  std::uint64_t singleSteps() const { return single_steps_; }

 private:
  enum class Phase { Measure, Probe, Settled };
  bool windowDone() const { return elapsed_ >= kWindow && steps_ >= kMinSteps; }
  void start(Phase p) {
    phase_ = p;
    elapsed_ = 0.0;
    steps_ = 0;
  }

  Phase phase_ = Phase::Measure;
  bool chosen_single_ = false;
  double elapsed_ = 0.0;  // s in this phase
  std::uint64_t steps_ = 0;
  double current_per_step_ = 0.0;
  double interval_ = kFirstInterval / 2;  // the first confirmation doubles it to kFirstInterval
  std::uint64_t probes_ = 0, switches_ = 0, single_steps_ = 0;
};

}  // namespace rocklab::sim::detail
