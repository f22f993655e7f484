#pragma once
// checkpoint.h5: everything needed to continue a run bit for bit: the scene text
// (every model parameter comes from it) and the full WorldState (time, step, dt,
// particle arrays including half-step velocities, contact history).
//
// Layout: attrs format = "rocklab-checkpoint", version = 1, time, step, dt,
// half_kick_pending, run_crc32 (CRC-32 of those four); /scene string; /particles/{position, velocity, omega [n,3],
// radius, inv_mass, inv_inertia, mass [n], material [n] int32, id [n] uint64};
// /pairs/{i, j [m] uint32, shear [m,3]}; /walls/{particle, wall [k] uint32, shear [k,3]};
// /moving_wall_work [1] J (absent in files written before it: 0); /experiment [b]
// uint8, the experiment driver's own state (only an experiment run that saves one:
// opaque bytes here, CBOR written and read by the experiments library).
// Doubles are stored as IEEE doubles, so a read gives back the same bits. Every
// dataset carries "unit" and "crc32" (CRC-32 of its bytes) attributes.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "rocklab/sim/world.h"

namespace rocklab::sim::output {

struct CheckpointError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Writes atomically (temporary file, then rename). A write that fails (a full
/// disk) throws OutputError (file_write.h) naming the file and the system's
/// reason, removes the temporary and leaves an existing checkpoint as it was; a
/// state whose arrays disagree throws CheckpointError.
/// `run_wall_time_s`: the wall time (s) the runs that led to this state took, this one
/// up to now included (a restart carries it on); NaN when not known (not written).
void writeCheckpoint(const std::filesystem::path& path, const WorldState& state,
                     const std::string& scene_text, std::span<const std::uint8_t> experiment_state = {},
                     double run_wall_time_s = std::numeric_limits<double>::quiet_NaN());

struct Checkpoint {
  WorldState state;
  std::string scene_text;
  std::vector<std::uint8_t> experiment_state;  // empty: the run saved none
  // s, wall time of the runs that led to this state; NaN: not saved (older files)
  double run_wall_time_s = std::numeric_limits<double>::quiet_NaN();
  // Datasets (and the block of run attributes) read without a checksum: files
  // written before checksums were stored are read, but unchecked.
  std::size_t unchecked = 0;
};
/// Throws CheckpointError naming the file and what is wrong with it: a missing
/// or misshapen dataset, array sizes that disagree, a checksum that does not
/// match (random damage). The values themselves are checked by the World that
/// restarts from them (World(Model, WorldState): dataset, row, what is allowed).
Checkpoint readCheckpoint(const std::filesystem::path& path);

}  // namespace rocklab::sim::output
