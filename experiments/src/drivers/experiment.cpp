#include "drivers/experiment.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace rocklab::experiments {

std::uint64_t stepsIn(double interval, double dt) {
  return static_cast<std::uint64_t>(std::clamp(std::round(interval / dt), 1.0, kMaxSteps));
}

std::unordered_map<std::uint64_t, BodyRef> indexBodies(const sim::ParticleState& p) {
  std::unordered_map<std::uint64_t, BodyRef> bodies;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.clump.empty() || p.clump[i] < 0) bodies[p.id[i]] = {false, static_cast<std::uint32_t>(i)};
  for (std::size_t c = 0; c < p.clumps.size(); ++c) bodies[p.clumps.id[c]] = {true, static_cast<std::uint32_t>(c)};
  return bodies;
}

geometry::Vec3 bodyPosition(const sim::ParticleState& p, const BodyRef& b) {
  return b.clump ? p.clumps.position[b.index] : p.position[b.index];
}

double bodyMass(const sim::ParticleState& p, const BodyRef& b) {
  return b.clump ? p.clumps.mass[b.index] : p.mass[b.index];
}

double maxBallSpeed(const sim::ParticleState& p, const std::vector<bool>& skip) {
  double v2 = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (skip.empty() || !skip[i]) v2 = std::max(v2, p.velocity[i].squaredNorm());
  return std::sqrt(v2);
}

geometry::Vec3 tiltedGravity(double g, double angle_deg, bool rotate) {
  const double a = angle_deg * std::numbers::pi / 180.0;
  return rotate ? geometry::Vec3(-g * std::sin(a), 0, -g * std::cos(a)) : geometry::Vec3(-g * std::tan(a), 0, -g);
}

std::size_t wallIndex(const sim::Model& model, const std::string& name) {
  for (std::size_t k = 0; k < model.walls.size(); ++k)
    if (model.walls[k].name == name) return k;
  throw std::logic_error("no wall named '" + name + "'");
}

void switchPhase(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx,
                 const std::function<void(sim::Model&)>& edit, const std::vector<bool>& remove) {
  sim::Model model = world->model();
  edit(model);
  sim::WorldState state = world->exportState();
  if (!remove.empty()) state = sim::withoutBalls(std::move(state), remove);
  world = std::make_unique<sim::World>(std::move(model), std::move(state), ctx.threads);
}

void switchState(std::unique_ptr<sim::World>& world, const ExperimentContext& ctx,
                 const std::function<void(sim::WorldState&)>& edit) {
  sim::Model model = world->model();
  sim::WorldState state = world->exportState();
  edit(state);
  world = std::make_unique<sim::World>(std::move(model), std::move(state), ctx.threads);
}

}  // namespace rocklab::experiments
