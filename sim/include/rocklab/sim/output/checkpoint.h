#pragma once
// checkpoint.h5: everything needed to continue a run bit for bit: the scene text
// (every model parameter comes from it) and the full WorldState (time, step, dt,
// particle arrays including half-step velocities, contact history).
//
// Layout: attrs format = "rocklab-checkpoint", version = 1, time, step, dt,
// half_kick_pending; /scene string; /particles/{position, velocity, omega [n,3],
// radius, inv_mass, inv_inertia, mass [n], material [n] int32, id [n] uint64};
// /pairs/{i, j [m] uint32, shear [m,3]}; /walls/{particle, wall [k] uint32, shear [k,3]}.
// Doubles are stored as IEEE doubles, so a read gives back the same bits.
#include <filesystem>
#include <stdexcept>
#include <string>

#include "rocklab/sim/world.h"

namespace rocklab::sim::output {

struct CheckpointError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Writes atomically (temporary file, then rename).
void writeCheckpoint(const std::filesystem::path& path, const WorldState& state,
                     const std::string& scene_text);

struct Checkpoint {
  WorldState state;
  std::string scene_text;
};
/// Throws CheckpointError naming the file and what is wrong with it.
Checkpoint readCheckpoint(const std::filesystem::path& path);

}  // namespace rocklab::sim::output
