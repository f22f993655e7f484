// Stability: initial overlaps up to 50 % of a radius with and without the
// relaxation of initial overlaps (Model::relaxation), a dense pile at rest
// (energy drift, creep; 2e4 steps here, 1e6 under [validation]), damping 1 and
// friction 10 in the pile, and a time step forced above the critical one.
#include <catch2/catch.hpp>

#include <optional>

#include "rocklab/sim/timestep.h"
#include "stability_support.h"

using namespace rocklab;
using namespace rocklab::stab;

namespace {

// --------------------------------------------------------------------------
// Two rocks created overlapping by a fraction of the radius (no gravity).

struct Release {
  Outcome o;
  double speed = 0.0;  // m/s, relative speed at the end
  double dt = 0.0;
};

Release release(double fraction, int relax_steps, double k = 1e9) {
  sim::Model model = linearPair(k, 0.37);
  model.relaxation.steps = relax_steps;
  // Breakage replacement overlaps by up to half a radius: without relaxation the
  // default limit 0.5 would stop such a state at once (round-off puts it just
  // above); with relaxation the watchdog sees only the overlap beyond the offset.
  if (relax_steps == 0) model.watchdog.max_overlap_fraction = 0.6;
  const double r = kRock;
  sim::World w(model, {sphere({0, 0, 0}, r), sphere({2 * r - fraction * r, 0, 0}, r)}, 1);
  Release rel;
  rel.dt = w.dt();
  rel.o = run(w, static_cast<std::uint64_t>(relax_steps) + 3000, 10);
  const auto& v = w.particles().velocity;
  rel.speed = (v[1] - v[0]).norm();
  return rel;
}

}  // namespace

TEST_CASE("initial overlap 10-50 % of the radius: released at once without relaxation", "[stability]") {
  const double r = kRock, k = 1e9, m_star = 0.5 * sphereMass(r);
  for (double f : {0.1, 0.3, 0.5}) {
    INFO("initial overlap " << f << " r");
    const Release rel = release(f, 0);
    REQUIRE(rel.o.finite);
    REQUIRE_FALSE(rel.o.stopped);
    // Undamped: the stored k d^2 / 2 all becomes kinetic energy, v = d sqrt(k / m*).
    const double predicted = f * r * std::sqrt(k / m_star);
    CHECK(rel.speed == Approx(predicted).epsilon(0.02));
    CHECK(rel.o.max_overlap <= f * (1 + 1e-9));
    figure("initial overlap " + num(f) + " r without relaxation",
           "released: relative speed " + num(rel.speed, 4) + " m/s (predicted " + num(predicted, 4) + ")");
  }
}

TEST_CASE("initial overlap 10-50 % of the radius: eased apart with relaxation over 5000 steps", "[stability]") {
  const double r = kRock;
  const int n = 5000;
  for (double f : {0.1, 0.3, 0.5}) {
    INFO("initial overlap " << f << " r");
    const Release rel = release(f, n);
    REQUIRE(rel.o.finite);
    REQUIRE_FALSE(rel.o.stopped);
    // The offset shrinks at 1.5 f r / (n dt) at most and the balls follow it
    // quasi-statically; they are left (nearly) at rest when it is gone.
    // Contacts only push: once the offset slows down the balls coast on at its
    // peak rate (each ball at half of it).
    const double rate = 1.5 * f * r / (n * rel.dt);
    const double released = f * r * std::sqrt(1e9 / (0.5 * sphereMass(r)));
    CHECK(rel.o.max_speed <= 0.55 * rate);
    CHECK(rel.speed <= 1.05 * rate);
    CHECK(rel.speed >= 0.9 * rate);
    figure("initial overlap " + num(f) + " r with relaxation 5000 steps",
           "eased apart: fastest " + num(rel.o.max_speed, 3) + " m/s (offset peak rate " + num(rate, 3) +
               "), final relative speed " + num(rel.speed, 3) + " m/s; without: " + num(released, 4) + " m/s");
  }
}

TEST_CASE("initial overlap 55 % of the radius: stopped at step 0 without relaxation - eased with it", "[stability]") {
  sim::Model model = linearPair(1e9, 0.37);
  const double r = kRock;
  const std::vector<sim::SphereSpec> s{sphere({0, 0, 0}, r), sphere({2 * r - 0.55 * r, 0, 0}, r)};
  {
    sim::World w(model, s, 1);
    const Outcome o = run(w, 10);
    REQUIRE(o.stopped);
    CHECK(o.steps == 0);
    CHECK_THAT(o.message, Catch::Contains("overlap of particle 0 with particle 1 is 0.55") &&
                              Catch::Contains("created overlapping (relaxation.steps eases"));
    figure("initial overlap 0.55 r, default watchdog, no relaxation",
           "stopped by the watchdog at step 0: " + o.message.substr(0, 120) + "...");
  }
  model.relaxation.steps = 5000;
  sim::World w(model, s, 1);
  const Outcome o = run(w, 8000, 10);
  REQUIRE(o.finite);
  CHECK_FALSE(o.stopped);
  CHECK(o.max_speed < 1.0);
  figure("initial overlap 0.55 r, default watchdog, relaxation 5000 steps",
         "eased apart: fastest " + num(o.max_speed, 3) + " m/s");
}

TEST_CASE("a lone ball created 30 % into a floor: eased out with relaxation, not shot off", "[stability]") {
  // No ball pair in the list at all: the wall's offset alone must relax (it was
  // ignored while only the pair list decided whether a relaxation runs).
  const double r = kRock, f = 0.3;
  const int n = 5000;
  auto fastest = [&](int relax_steps) {
    sim::Model model = linearPair(1e9);
    model.walls = {test::floorPlane()};
    model.relaxation.steps = relax_steps;
    sim::World w(model, {sphere({0, 0, r - f * r}, r)}, 1);
    const Outcome o = run(w, static_cast<std::uint64_t>(relax_steps) + 3000, 10);
    REQUIRE(o.finite);
    REQUIRE_FALSE(o.stopped);
    return std::pair{o.max_speed, w.dt()};
  };
  const auto [released, dt_released] = fastest(0);
  const auto [eased, dt] = fastest(n);
  // The offset shrinks at 1.5 f r / (n dt) at most; the ball follows it.
  const double rate = 1.5 * f * r / (n * dt);
  CHECK(eased <= 1.05 * rate);
  CHECK(released > 100 * eased);
  figure("a lone ball 0.3 r into a floor", "with relaxation 5000 steps: fastest " + num(eased, 3) +
                                               " m/s (offset peak rate " + num(rate, 3) + "); without: " +
                                               num(released, 4) + " m/s");
}

TEST_CASE("breakage replacement: a 4 mm fragment between two rocks overlapping both by half its radius", "[stability]") {
  // Floor, rock, fragment, rock on one vertical line under gravity; the fragment
  // overlaps each rock by 1 mm (50 % of its radius). Study pebble stiffness 1e9 N/m.
  for (int relax : {0, 200000}) {
    INFO("relaxation steps " << relax);
    sim::Model model = linearPair(1e9, 0.37, 0.11);
    model.gravity = Vec3(0, 0, -9.81);
    model.walls.push_back(plane("floor", Vec3::Zero(), Vec3::UnitZ()));
    model.relaxation.steps = relax;
    model.watchdog.max_overlap_fraction = 0.6;
    const double R = kRock, r = kFragment, d = 0.5 * r;
    const double z1 = R, z2 = z1 + R + r - d, z3 = z2 + r + R - d;
    sim::World w(model, {sphere({0, 0, z1}, R), sphere({0, 0, z2}, r), sphere({0, 0, z3}, R)}, 1);
    const Outcome o = run(w, static_cast<std::uint64_t>(relax) + 30000, 100, {}, relax == 0);
    REQUIRE(o.finite);
    REQUIRE_FALSE(o.stopped);
    const double top_speed = w.particles().velocity[2].norm();
    const double rate = 1.5 * d / (relax * w.dt());  // peak rate of the offsets
    if (relax == 0) {
      // The fragment's overlap energy k d^2 per side throws the top rock up.
      CHECK(o.max_speed > 10.0);
      figure("fragment overlapping two rocks by 0.5 r, no relaxation",
             "released: fastest " + num(o.max_speed, 3) + " m/s (energy of the overlaps turned kinetic)");
    } else {
      // Each offset shrinks by d; the top rock rises by up to 2 d, at most at twice the rate.
      CHECK(o.max_speed < 2.2 * rate);
      CHECK(top_speed < 2.2 * rate);
      // Relaxed: only the weights press, m g / k = 3e-10 m per contact.
      CHECK(maxOverlapFraction(w) < 1e-3);
      figure("fragment overlapping two rocks by 0.5 r, relaxation 200000 steps",
             "eased: fastest " + num(o.max_speed, 3) + " m/s (offset peak rate " + num(rate, 3) +
                 " m/s), final overlap " + num(maxOverlapFraction(w), 3) + " of the fragment radius");
    }
  }
}

namespace {

// --------------------------------------------------------------------------
// A dense pile of 128 rocks (r 12-14 mm) in a 130 mm box: a jittered column
// lattice collapses under gravity with the study's damping (0.11), then the
// velocities are zeroed twice (as the study's freeze does) so that no ball keeps
// rolling freely on the floor. (Cundall local damping 0.7 was tried for the
// settling: it slows the collapse to a creep that lasts seconds.)

sim::Model pileModel(double beta, double friction = 0.37) {
  sim::Model m = linearPair(1e7, friction, beta);  // the demo's trimmed stiffness
  m.gravity = Vec3(0, 0, -9.81);
  const double L = 0.13;
  m.walls = {plane("floor", Vec3::Zero(), Vec3::UnitZ()), plane("x0", Vec3::Zero(), Vec3::UnitX()),
             plane("x1", Vec3(L, 0, 0), -Vec3::UnitX()), plane("y0", Vec3::Zero(), Vec3::UnitY()),
             plane("y1", Vec3(0, L, 0), -Vec3::UnitY())};
  return m;
}

void stopAll(sim::WorldState& state) {
  for (Vec3& v : state.particles.velocity) v.setZero();
  for (Vec3& w : state.particles.omega) w.setZero();
}

const sim::WorldState& settledPile() {
  static std::optional<sim::WorldState> state;
  if (state) return *state;
  std::vector<sim::SphereSpec> s;
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const int n = static_cast<int>(s.size());
        const double r = 0.012 + 0.002 * std::fmod(n * 0.6180339887, 1.0);
        const double jx = 0.002 * std::fmod(n * 0.7548776662, 1.0) - 0.001;
        const double jy = 0.002 * std::fmod(n * 0.5698402910, 1.0) - 0.001;
        s.push_back(sphere({0.017 + 0.032 * i + jx, 0.017 + 0.032 * j + jy, 0.016 + 0.032 * k}, r));
      }
  const sim::Model model = pileModel(0.11);
  sim::WorldState st;
  {
    sim::World w(model, s, 1);
    // Collapse for 1.0 s, then two rounds of 0.14 s (the step-count version of
    // this was written for safety factor 0.5: same simulated times).
    while (w.time() < 1.0) w.step();
    st = w.exportState();
  }
  for (int round = 0; round < 2; ++round) {
    stopAll(st);
    sim::World w(model, st, 1);
    const double end = w.time() + 0.14;
    while (w.time() < end) w.step();
    st = w.exportState();
  }
  stopAll(st);
  st.step = 0;  // the rest phase counts its own steps
  st.time = 0;
  state = st;
  return *state;
}

struct Rest {
  Outcome o;
  double creep = 0.0;        // largest displacement of a ball / its radius
  double drift = 0.0;        // (E_max - E_first) / scale
  double scale = 0.0;        // J, sum of m g r over the balls
  double dt_over_crit = 0.0;
  double network = 0.0;      // largest dt / stable step of the contact network (stops above 1)
};

Rest rest(const sim::Model& model, std::uint64_t steps, std::uint64_t every = 100, double dt = 0.0) {
  sim::WorldState state = settledPile();
  if (dt > 0) state.dt = dt;
  else state.dt = sim::World(model, settledPile(), 1).timestepAudit().automatic;
  sim::World w(model, state, 1);
  Rest r;
  r.dt_over_crit = w.dt() / w.timestepAudit().critical;
  const auto x0 = w.particles().position;
  r.o = run(w, steps, every, {}, false);
  const auto& p = w.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    r.creep = std::max(r.creep, (p.position[i] - x0[i]).norm() / p.radius[i]);
    r.scale += p.mass[i] * 9.81 * p.radius[i];
  }
  r.o.max_overlap = maxOverlapFraction(w);
  r.network = w.stats().network_step_ratio;
  r.drift = (r.o.e_max - r.o.e_first) / r.scale;
  return r;
}

// Creep allowed at rest: 1e-7 r. Measured 5.6e-11 to 1.5e-10 r in every stable
// case (docs/stability.md: 2e4 and 1e6 steps, beta 0 / 0.11 / 1, friction 10),
// so round-off and compiler changes keep far below it, while the weakly unstable
// mode of the former default step (0.5 x critical: creep 8.2e-6 r in 2e4 steps)
// is 80 times above it. (It was 0.01 r: a pile could slide 1e8 times its
// measured creep unseen.)
constexpr double kCreepLimit = 1e-7;

void checkRest(const Rest& r, const std::string& name, double creep_limit = kCreepLimit) {
  REQUIRE(r.o.finite);
  REQUIRE_FALSE(r.o.stopped);
  CHECK(r.drift < 1e-3);            // no energy from nowhere
  CHECK(r.creep < creep_limit);     // the pile stays where it is
  CHECK(r.o.max_overlap < 0.05);    // weight only: m g / k per contact is ~1e-4 r
  figure(name, "stable: " + std::to_string(r.o.steps) + " steps, energy rise " + num(r.drift, 3) +
                   " of sum m g r, creep " + num(r.creep, 3) + " r, final overlap " + num(r.o.max_overlap, 3) +
                   " r, KE/scale " + num(r.o.ke_last / r.scale, 3) +
                   ", network step ratio " + num(r.network, 3));
}

}  // namespace

TEST_CASE("dense pile of 128 rocks at rest for 2e4 steps: damping 0.11 and 0", "[stability]") {
  for (double beta : {0.11, 0.0}) {
    INFO("damping " << beta);
    const Rest r = rest(pileModel(beta), 20000);
    checkRest(r, "pile at rest 2e4 steps damping " + num(beta));
  }
}

TEST_CASE("dense pile of 128 rocks at rest for 1e6 steps: damping 0.11 and 0", "[stability][validation]") {
  for (double beta : {0.11, 0.0}) {
    INFO("damping " << beta);
    const Rest r = rest(pileModel(beta), 1000000, 1000);
    checkRest(r, "pile at rest 1e6 steps damping " + num(beta));
  }
}

TEST_CASE("dense pile with damping 1 at the automatic step", "[stability]") {
  // At the step before the damped cap (0.5 x critical) this pile crept by 0.93 r
  // in 2e4 steps (beta = 1, and beta_n = 1 alone), unseen by the watchdog.
  const Rest r = rest(pileModel(1.0), 20000);
  checkRest(r, "pile at rest 2e4 steps damping 1 (dt/critical " + num(r.dt_over_crit, 3) + ")");
  sim::Model normal_only = pileModel(0.11);
  normal_only.contact.damping_normal = 1.0;
  const Rest n = rest(normal_only, 20000);
  checkRest(n, "pile at rest 2e4 steps damping normal 1 shear 0.11 (dt/critical " + num(n.dt_over_crit, 3) + ")");
}

TEST_CASE("dense pile with friction 10 at safety factor 0.25", "[stability]") {
  sim::Model model = pileModel(0.11, 10.0);
  model.timestep.safety_factor = 0.25;
  const Rest r = rest(model, 20000);
  checkRest(r, "pile at rest 2e4 steps friction 10, safety factor 0.25");
}

// With every contact stuck (friction 10, ks = kn) and the study's dashpots, the
// pile's coupled shear-and-spin modes were unstable at the former default step
// (0.5 x critical): it crept by 0.0104 r in 2e4 steps with its energy rising by
// 8.6e-4 of sum m g r, unseen by the watchdog; its contact-network step ratio was
// 1.02. The default is now 0.4 x critical, capped at 0.6 x the damped limit.
TEST_CASE("dense pile with friction 10 at the automatic step", "[stability]") {
  const Rest r = rest(pileModel(0.11, 10.0), 20000);
  CHECK(r.network < 1.0);
  checkRest(r, "pile at rest 2e4 steps friction 10 (dt/critical " + num(r.dt_over_crit, 3) + ")");
}

namespace {

// The pile at dt = factor x critical (allow_unsafe). With `stop_message` empty
// it must stay stable, else be stopped within one check interval by the check
// whose message contains it.
void forcedStep(double factor, const std::string& stop_message) {
  const sim::Model base = pileModel(0.11);
  const double crit = sim::World(base, settledPile(), 1).timestepAudit().critical;
  INFO("dt = " << factor << " x critical");
  sim::Model model = base;
  model.timestep.allow_unsafe = true;
  const Rest r = rest(model, 20000, 10, factor * crit);
  REQUIRE(r.o.finite);
  const std::string name = "forced dt " + num(factor) + " x critical";
  if (stop_message.empty()) {
    REQUIRE_FALSE(r.o.stopped);
    CHECK(r.drift < 1e-3);
    CHECK(r.creep < kCreepLimit);
    figure(name, "stable: energy rise " + num(r.drift, 3) + ", creep " + num(r.creep, 3) + " r, network step ratio " +
                     num(r.network, 3));
    return;
  }
  REQUIRE(r.o.stopped);
  CHECK_THAT(r.o.message, Catch::Contains("watchdog") && Catch::Contains("x the critical step"));
  CHECK_THAT(r.o.message, Catch::Contains(stop_message));
  // Far above the limit the first check (step 0) sees it; near it (0.5: ratio
  // 1.04) the power iteration needs a few checks (every 500 steps) of 4
  // iterations to converge.
  CHECK(r.o.steps <= (factor >= 1 ? 100u : 5000u));
  figure(name, "stopped by the watchdog at step " + std::to_string(r.o.steps) + ": " + r.o.message.substr(0, 110) + "...");
}

}  // namespace

TEST_CASE("time step forced to 2-10 x the critical one: the watchdog stops the pile", "[stability]") {
  for (double f : {2.0, 3.0, 5.0, 10.0}) forcedStep(f, "the step is unstable for the contact network");
}

// Between 1 and 2 x critical the pile used to creep with its energy falling
// (0.15 r and 0.91 r in 2e4 steps at 1 and 1.5 x), unseen by the energy and
// overlap checks; the contact-network check stops it at its first check.
TEST_CASE("time step forced to 0.4-1.5 x the critical one: stable at the default - stopped from the former default up", "[stability]") {
  forcedStep(0.4, "");
  for (double f : {0.5, 1.0, 1.5}) forcedStep(f, "the step is unstable for the contact network");
}

TEST_CASE("relaxation survives a restart from the exported state bit for bit", "[stability]") {
  // The offsets travel in the contact history (PairHistory/WallHistory::relax_offset).
  sim::Model model = linearPair(1e9, 0.37, 0.11);
  model.gravity = Vec3(0, 0, -9.81);
  model.walls.push_back(plane("floor", Vec3::Zero(), Vec3::UnitZ()));
  model.relaxation.steps = 4000;
  const double r = kRock;
  const std::vector<sim::SphereSpec> s{sphere({0, 0, 0.6 * r}, r), sphere({0, 0, 2.2 * r}, r),
                                       sphere({0.5 * r, 0, 3.6 * r}, r)};
  sim::World a(model, s, 1);
  for (int k = 0; k < 1500; ++k) a.step();
  const sim::WorldState mid = a.exportState();
  bool carried = false;
  for (const sim::PairHistory& h : mid.pair_history) carried = carried || h.relax_offset > 0;
  for (const sim::WallHistory& h : mid.wall_history) carried = carried || h.relax_offset > 0;
  CHECK(carried);
  sim::World b(model, mid, 1);
  for (int k = 0; k < 4000; ++k) {
    a.step();
    b.step();
  }
  CHECK(a.stateHash() == b.stateHash());
}

namespace {

/// The energy balance of a pile driven by its moving floor (wall 0): every 100th
/// step E(t) - E(0) - W(t), with W the floor's work on the balls summed by the
/// test from the floor's load cell, -F(t_k) . v_floor(t_k) dt per step,
/// independently of the engine's own count.
struct Balance {
  Outcome o;
  double work = 0.0;          // J, W at the end
  double worst_excess = -1e300;  // J, largest E - E(0) - W: energy from nowhere
  double worst_deficit = 1e300;  // J, smallest E - E(0) - W: dissipated (dashpots, slip)
  double rise = 0.0;          // J, largest E - E(0): what an uncounted check would see
  double scale = 0.0;         // J, the watchdog's energy scale at the start
  double overlap = 0.0;       // largest ball-ball overlap / smaller radius at the end
};

Balance balance(const sim::Model& model, const std::function<Vec3(double)>& v_floor, std::uint64_t steps) {
  sim::WorldState state = settledPile();
  state.dt = sim::World(model, settledPile(), 1).timestepAudit().automatic;
  sim::World w(model, state, 1);
  Balance b;
  {
    // The scale the watchdog takes at its first check (stages/watchdog.cpp):
    // |kinetic + elastic| (0 at rest, up to round-off) + m |g| (extent + 2 r_max).
    const sim::ParticleState& p = w.particles();
    Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
    double mass = 0, r_max = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      lo = lo.cwiseMin(p.position[i]);
      hi = hi.cwiseMax(p.position[i]);
      mass += p.mass[i];
      r_max = std::max(r_max, p.radius[i]);
    }
    b.scale = mass * model.gravity.norm() * ((hi - lo).norm() + 2 * r_max);
  }
  // Every step observed: the load cell is read inside the step, where balls and
  // floor are both at t (after the step the balls have drifted to t + dt while the
  // floor's pose is still that of t: 1.5e-6 m at 0.15 m/s, ten times the overlaps
  // under the pile's weight).
  double e0 = 0.0;
  const std::function<void(const sim::Snapshot&)> observe = [&](const sim::Snapshot& s) {
    const double e = s.energy.total();
    if (s.step == 0) e0 = e;
    if (s.step % 100 == 0) {
      b.worst_excess = std::max(b.worst_excess, e - e0 - b.work);
      b.worst_deficit = std::min(b.worst_deficit, e - e0 - b.work);
      b.rise = std::max(b.rise, e - e0);
    }
    b.work -= w.wallForces()[0].dot(v_floor(s.time)) * w.dt();
  };
  try {
    for (std::uint64_t k = 0; k < steps; ++k) {
      w.step(observe);
      b.o.steps = k + 1;
    }
  } catch (const sim::WatchdogError& e) {
    b.o.stopped = true;
    b.o.message = e.what();
  }
  b.o.finite = allFinite(w);
  b.overlap = maxOverlapFraction(w);
  return b;
}

}  // namespace

TEST_CASE("the settled pile on a shaking floor (3.6 g): the wall's work is counted - no false alarm", "[stability]") {
  // Legitimate work input: a floor oscillating 1 mm at 30 Hz under the pile
  // fluidises it. The energy check (which counts the floor's work since it moves)
  // must stay quiet, and the overlaps small.
  sim::Model model = pileModel(0.11);
  sim::Wall floor = squareZ("floor", Vec3(0.065, 0.065, 0), 0.2);
  const double A = 1e-3, f = 30.0, omega = 2 * std::numbers::pi * f;
  floor.motion.amplitude = Vec3(0, 0, A);
  floor.motion.frequency = f;
  model.walls[0] = floor;
  const Balance b = balance(model, [&](double t) { return Vec3(0, 0, A * omega * std::cos(omega * t)); }, 20000);
  REQUIRE(b.o.finite);
  INFO(b.o.message);
  CHECK_FALSE(b.o.stopped);
  // No energy from nowhere: E - E(0) never exceeds the floor's work by more
  // than 1e-3 of the scale (the O(dt) error of summing the work per step, and
  // the dashpots' share of the floor's force, which its load cell leaves out).
  CHECK(b.worst_excess < 1e-3 * b.scale);
  // The floor really works: it puts in more than 1 % of the scale, and the pile
  // (dashpots, slip) dissipates some of it.
  CHECK(b.work > 0.01 * b.scale);
  CHECK(b.worst_deficit < 0.0);
  CHECK(b.overlap < 0.05);
  figure("pile on a floor shaking 1 mm at 30 Hz (3.6 g), 2e4 steps",
         "stable, not stopped: floor's work " + num(b.work, 3) + " J, E - E0 - W in [" + num(b.worst_deficit, 3) +
             ", " + num(b.worst_excess, 3) + "] J (scale " + num(b.scale, 3) + " J)");
}

TEST_CASE("the settled pile lifted by its floor at 0.15 m/s: the wall's work is counted - no false alarm", "[stability]") {
  // The floor lifts the 3.5 kg pile by 4 cm: about 1.4 J of potential energy, more
  // than 10 % of the energy scale (7.2 J). Uncounted, that work would read as
  // "energy growth with no work input".
  sim::Model model = pileModel(0.11);
  model.walls[0].motion.velocity = Vec3(0, 0, 0.15);
  const Balance b = balance(model, [](double) { return Vec3(0, 0, 0.15); }, 20000);
  REQUIRE(b.o.finite);
  INFO(b.o.message);
  CHECK_FALSE(b.o.stopped);
  // The balance all along: E(t) - E(0) - W(t) never above 1e-3 of the scale (the
  // O(dt) error of summing the work, the dashpots the load cell leaves out), and
  // never below -W: the pile cannot dissipate more than the floor put in. It does
  // dissipate much of it (measured: W 2.14 J, E - E(0) 1.03 J): the pile slides
  // up the static side walls with friction 0.37, which carry part of its weight.
  CHECK(b.worst_excess < 1e-3 * b.scale);
  CHECK(b.worst_deficit > -b.work);
  CHECK(b.work > 0.1 * b.scale);
  // Without W the check would trip: the rise is above watchdog.max_energy_growth x scale.
  CHECK(b.rise > model.watchdog.max_energy_growth * b.scale);
  figure("pile lifted by its floor at 0.15 m/s, 2e4 steps",
         "not stopped: floor's work " + num(b.work, 3) + " J, energy gained " + num(b.rise, 3) +
             " J, E - E0 - W in [" + num(b.worst_deficit, 3) + ", " + num(b.worst_excess, 3) + "] J (scale " +
             num(b.scale, 3) + " J)");
}
