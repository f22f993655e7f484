#pragma once
// run.h5: the trajectory file of one run (HDF5).
//
// Layout (all values SI; every dataset carries a "unit" string attribute and,
// but for the growing /energy table, "crc32", the CRC-32 of its bytes):
//   /                      attrs: format = "rocklab-run", version = 1, complete (int 0/1),
//                                 interrupted (int 0/1)
//   /scene                 string dataset: the scene file text as run (after --set overrides)
//   /frames/000000, ...    one group per frame, attrs time (s), step;
//                          datasets position [n,3] m, velocity [n,3] m/s, omega [n,3] rad/s,
//                          force [n,3] N, radius [n] m, id [n] uint64, material [n] int32,
//                          wall_active [walls] uint8 (1 = the wall exists in this frame)
//                          with clumps also: clump [n] int32 (owning clump, -1 free),
//                          clump_position [c,3] m, clump_velocity [c,3] m/s, clump_omega [c,3]
//                          rad/s, clump_orientation [c,4] (x, y, z, w; body -> world), clump_id [c]
//                          with parallel bonds also: bond_intact [bonds] uint8 (1 while bond k
//                          holds); bond_a, bond_b [bonds] uint32 only when they differ from
//                          /bonds (balls removed and renumbered during the run)
//   /bonds                 once per file, with parallel bonds: bond_a, bond_b [bonds] uint32,
//                          the balls (indices into a frame's ball arrays) bond k joins
//   /energy                [rows, 8] double, extendible and chunked; columns (attr "columns"):
//                          time s, step, kinetic_translational J, kinetic_rotational J,
//                          potential_gravity J, elastic J, total J, contacts
//   /materials/000000, ... the run's materials table (sim::Model::materials), one group per
//                          row: name (string), properties [6] double (attr "columns": density
//                          kg/m^3, kn N/m, ks N/m, friction, shear_modulus Pa, poisson),
//                          made_from [1] int32 (Material::made_from: -1, or the earlier row it
//                          was copied from). A row is written, with the frame that first can
//                          use it, when the table grows (a breakage's fragment classes); the
//                          frames' material indices are rows of it. Files written before
//                          2026-12-05, and by writers that pass no table, have none (their
//                          frames use only the scene's materials).
//
// Safe writing: the file is written as `<path>.partial` and renamed to `<path>`
// by close(), so a good run.h5 is never replaced by a half-written one. The file
// is flushed after every frame, so even the .partial of a killed run is readable.
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rocklab/sim/model.h"
#include "rocklab/sim/snapshot.h"

namespace rocklab::sim::output {

class RunFile {
 public:
  RunFile(const std::filesystem::path& path, const std::string& scene_text);
  /// closes without renaming if close() was not called (keeps the .partial of a
  /// killed run readable); after a failed write, discards it.
  ~RunFile();
  RunFile(const RunFile&) = delete;
  RunFile& operator=(const RunFile&) = delete;

  /// A failure (a full disk) throws OutputError (file_write.h) naming the file and
  /// the system's reason; the file is failed() from then on. `materials`: the
  /// run's materials table at this frame (the world's Model::materials); its rows
  /// not yet in /materials go there first, in the frame's flush, so a frame's
  /// materials survive a kill with it. Rows are only ever added: a shorter table,
  /// or a made_from that is not an earlier row, throws std::invalid_argument.
  void writeFrame(const Snapshot& snapshot, std::span<const Material> materials = {});
  void appendEnergy(const Snapshot& snapshot);
  std::size_t frameCount() const;
  /// Marks the file complete (or interrupted), closes it and renames it into
  /// place. Throws OutputError when that fails (the .partial is removed then).
  void close(bool interrupted);
  /// A write failed: the file cannot be finished, only discard()ed.
  bool failed() const;
  /// Closes and removes the .partial (a failed run keeps no half-written trajectory).
  void discard() noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads a run.h5 (or its .partial) back: the scene text and the frames, for
/// re-rendering from another camera or for analysis. Throws std::runtime_error
/// naming the file when it is not a rocklab run file.
class RunFileReader {
 public:
  explicit RunFileReader(const std::filesystem::path& path);
  ~RunFileReader();
  RunFileReader(const RunFileReader&) = delete;
  RunFileReader& operator=(const RunFileReader&) = delete;

  const std::string& sceneText() const;
  /// /materials: the run's materials table as of its last stored frame (the
  /// scene's and those made during the run); empty when the file has none.
  const std::vector<Material>& materials() const;
  std::size_t frameCount() const;
  /// Frame k as a snapshot (energy not included); valid until the next call.
  /// Throws std::runtime_error naming the file, the frame, and for a bad bond
  /// row the dataset and row (a wrong length, a missing ball, a self-bond).
  const Snapshot& frame(std::size_t k);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rocklab::sim::output
