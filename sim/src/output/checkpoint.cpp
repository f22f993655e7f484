#include "rocklab/sim/output/checkpoint.h"

#include <H5Cpp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "hdf5_io.h"
#include "rocklab/sim/output/file_write.h"
#include "state_check.h"

namespace rocklab::sim::output {
namespace {

using detail::Layout;
using detail::writeArray;
using detail::writeScalarAttribute;
using detail::writeText;
using detail::writeTextAttribute;

constexpr const char* kFormat = "rocklab-checkpoint";
constexpr int kFormatVersion = 1;

/// The contact-history arrays are stored column by column: two uint32 indices
/// and the shear force [k,3] N.
template <class History>
struct HistoryLayout {
  const char* group;
  const char* first_name;
  std::uint32_t History::*first;
  const char* second_name;
  std::uint32_t History::*second;
};
constexpr HistoryLayout<PairHistory> kPairLayout{"pairs", "i", &PairHistory::i, "j",
                                                 &PairHistory::j};
constexpr HistoryLayout<WallHistory> kWallLayout{"walls", "particle", &WallHistory::particle,
                                                 "wall", &WallHistory::wall};

std::string quoted(const std::filesystem::path& path) {
  return "'" + path.string() + "'";
}

std::string describe(const H5::Exception& e) {
  return "HDF5 error in " + e.getFuncName() + ": " + e.getDetailMsg();
}

/// "" or what makes the state's arrays unusable together (state_check.h).
std::string inconsistency(const WorldState& state) { return sim::detail::stateShapeProblem(state); }

// ---------------------------------------------------------------- writing

/// One member of every element, in order.
template <class Row, class Member>
std::vector<Member> column(const std::vector<Row>& rows, Member Row::*member) {
  std::vector<Member> values;
  values.reserve(rows.size());
  for (const Row& row : rows) values.push_back(row.*member);
  return values;
}

template <class History>
void writeHistory(const H5::Group& root, const HistoryLayout<History>& layout,
                  const std::vector<History>& rows) {
  const H5::Group group = root.createGroup(layout.group);
  writeArray(group, layout.first_name, column(rows, layout.first), "");
  writeArray(group, layout.second_name, column(rows, layout.second), "");
  writeArray(group, "shear", column(rows, &History::shear), "N");
  // Only while initial overlaps are being relaxed (Model::relaxation).
  bool relaxing = false;
  for (const History& row : rows) relaxing = relaxing || row.relax_offset != 0.0;
  if (relaxing) writeArray(group, "relax_offset", column(rows, &History::relax_offset), "m");
}

/// Mesh walls' contact slots and last normals (WallHistory), only when a row has one.
void writeWallSlots(const H5::Group& root, const std::vector<WallHistory>& rows) {
  const bool any = std::any_of(rows.begin(), rows.end(),
                               [](const WallHistory& h) { return h.slot != 0 || !h.normal.isZero(0); });
  if (!any) return;
  const H5::Group group = root.openGroup(kWallLayout.group);
  writeArray(group, "slot", column(rows, &WallHistory::slot), "");
  writeArray(group, "normal", column(rows, &WallHistory::normal), "");
}

void writeParticles(const H5::Group& root, const ParticleState& p) {
  const H5::Group group = root.createGroup("particles");
#define ROCKLAB_WRITE(type, name, unit, meaning) writeArray(group, #name, p.name, unit);
  ROCKLAB_BALL_FIELDS(ROCKLAB_WRITE)
#undef ROCKLAB_WRITE
  if (p.clumps.size() == 0) return;
  const ClumpState& k = p.clumps;
  writeArray(group, "clump", p.clump, "");
  const H5::Group clumps = root.createGroup("clumps");
#define ROCKLAB_WRITE(type, name, unit, meaning) writeArray(clumps, #name, k.name, unit);
  ROCKLAB_CLUMP_FIELDS(ROCKLAB_WRITE)
#undef ROCKLAB_WRITE
  writeArray(clumps, "member_begin", k.member_begin, "");
  writeArray(clumps, "member_ball", k.member_ball, "");
  writeArray(clumps, "member_offset", k.member_offset, "m");
}

/// Bonds (only in a world that has them): every field of the bond table.
void writeBonds(const H5::Group& root, const BondState& b) {
  if (b.size() == 0) return;
  const H5::Group group = root.createGroup("bonds");
#define ROCKLAB_WRITE(type, name, unit, meaning) writeArray(group, #name, b.name, unit);
  ROCKLAB_BOND_FIELDS(ROCKLAB_WRITE)
#undef ROCKLAB_WRITE
}

/// The run attributes (time, step, dt, half_kick_pending) as one block of bytes,
/// for their checksum (the datasets carry their own).
struct RunScalars {
  double time;
  std::uint64_t step;
  double dt;
  std::int32_t half_kick_pending;
  std::int32_t zero = 0;  // padding with a known value
};
static_assert(sizeof(RunScalars) == 32);
std::uint32_t runScalarsChecksum(const RunScalars& r) { return detail::checksum(&r, sizeof r); }
constexpr const char* kRunChecksum = "run_crc32";

/// The checkpoint file's bytes, built in memory: HDF5 never meets the disk, so
/// a full disk is one failed write() with its errno (writeFileAtomically).
std::string fileImage(const std::string& name, const WorldState& state, const std::string& scene_text,
                      std::span<const std::uint8_t> experiment_state, double run_wall_time_s) {
  detail::FileHandle handle(name, true);
  const H5::Group& file = handle.root();
  writeTextAttribute(file, "format", kFormat);
  writeScalarAttribute(file, "version", H5::PredType::NATIVE_INT, kFormatVersion);
  const RunScalars run{state.time, state.step, state.dt, state.half_kick_pending ? 1 : 0};
  writeScalarAttribute(file, "time", H5::PredType::NATIVE_DOUBLE, run.time);
  writeScalarAttribute(file, "step", H5::PredType::NATIVE_UINT64, run.step);
  writeScalarAttribute(file, "dt", H5::PredType::NATIVE_DOUBLE, run.dt);
  writeScalarAttribute(file, "half_kick_pending", H5::PredType::NATIVE_INT, run.half_kick_pending);
  writeScalarAttribute(file, kRunChecksum, H5::PredType::NATIVE_UINT32, runScalarsChecksum(run));
  writeText(file, "scene", scene_text);
  writeParticles(file, state.particles);
  writeHistory(file, kPairLayout, state.pair_history);
  writeHistory(file, kWallLayout, state.wall_history);
  writeWallSlots(file, state.wall_history);
  writeBonds(file, state.bonds);
  writeArray(file, "moving_wall_work", std::vector<double>{state.moving_wall_work}, "J");
  if (!experiment_state.empty()) writeArray(file, "experiment", experiment_state, "");
  if (std::isfinite(run_wall_time_s)) writeArray(file, "run_wall_time_s", std::vector<double>{run_wall_time_s}, "s");
  std::string image = handle.image();
  handle.close();
  return image;
}

// ---------------------------------------------------------------- reading

/// Reads one checkpoint file; every complaint names the file.
class Reader {
 public:
  explicit Reader(std::filesystem::path path)
      : path_(std::move(path)), file_(path_.string(), H5F_ACC_RDONLY) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw CheckpointError("checkpoint " + quoted(path_) + ": " + what);
  }

  void checkFormat() const {
    if (!file_.attrExists("format")) fail("not a rocklab checkpoint (no 'format' attribute)");
    const H5::Attribute stored = file_.openAttribute("format");
    std::string format;
    if (stored.getTypeClass() == H5T_STRING && points(stored.getSpace()) == 1) {
      stored.read(stored.getStrType(), format);
    }
    if (format != kFormat) {
      fail("not a rocklab checkpoint (format is '" + format + "', expected '" + kFormat + "')");
    }
    const int version = attribute<int>("version");
    if (version != kFormatVersion) {
      fail("unsupported checkpoint version " + std::to_string(version) + " (this build reads " +
           std::to_string(kFormatVersion) + ")");
    }
  }

  template <class T>
  T attribute(const char* name) const {
    try {
      return detail::readScalarAttribute<T>(file_, name, nativeScalarType<T>());
    } catch (const std::runtime_error& e) {  // missing, or not one value
      fail(e.what());
    }
  }

  bool has(const std::string& name) const { return file_.nameExists(name); }

  std::string text(const std::string& name) const {
    const H5::DataSet dataset = openDataSet(name);
    if (dataset.getTypeClass() != H5T_STRING || points(dataset.getSpace()) != 1) {
      fail("dataset " + name + " is not a single string");
    }
    std::string value;
    dataset.read(value, dataset.getStrType());
    verify(name, dataset, value.data(), value.size());
    return value;
  }

  /// The run attributes against their checksum (run_crc32; absent in old files).
  void verifyRunScalars(const RunScalars& run) const {
    const detail::ChecksumCheck c = [&] {
      detail::ChecksumCheck check;
      if (!file_.attrExists(kRunChecksum)) return check;
      check.present = true;
      check.stored = attribute<std::uint32_t>(kRunChecksum);
      check.computed = runScalarsChecksum(run);
      check.matches = check.stored == check.computed;
      return check;
    }();
    if (!c.present) ++unchecked_;
    if (!c.matches) fail("attributes time, step, dt, half_kick_pending: " + c.mismatch());
  }

  /// Datasets (and attribute blocks) read without a checksum to check them by.
  std::size_t unchecked() const { return unchecked_; }

  /// Reads a dataset of shape [n] or [n,3] (as Layout<T> says) into a vector.
  template <class T>
  std::vector<T> array(const std::string& name) const {
    const H5::DataSet dataset = openDataSet(name);
    const H5::DataSpace space = dataset.getSpace();
    const int rank = space.getSimpleExtentNdims();
    const int expected_rank = Layout<T>::columns == 0 ? 1 : 2;
    std::array<hsize_t, 2> dims{0, 0};
    if (rank == expected_rank) space.getSimpleExtentDims(dims.data());
    if (rank != expected_rank || (expected_rank == 2 && dims[1] != Layout<T>::columns)) {
      fail("dataset " + name + " has the wrong shape (expected " +
           (expected_rank == 1 ? std::string("[n]")
                               : "[n," + std::to_string(Layout<T>::columns) + "]") +
           ")");
    }
    std::vector<T> values(dims[0]);
    if (!values.empty()) dataset.read(values.data(), Layout<T>::type());
    verify(name, dataset, values.data(), values.size() * sizeof(T));
    return values;
  }

 private:
  void verify(const std::string& name, const H5::DataSet& dataset, const void* data, std::size_t bytes) const {
    const detail::ChecksumCheck c = detail::verifyChecksum(dataset, data, bytes);
    if (!c.present) ++unchecked_;
    if (!c.matches) fail("dataset " + name + ": " + c.mismatch());
  }

  static hssize_t points(const H5::DataSpace& space) { return space.getSimpleExtentNpoints(); }

  template <class T>
  static const H5::PredType& nativeScalarType() {
    if constexpr (std::is_same_v<T, int>) {
      return H5::PredType::NATIVE_INT;
    } else {
      return Layout<T>::type();
    }
  }

  /// Opens `name` (an absolute path), saying which part of it is missing.
  H5::DataSet openDataSet(const std::string& name) const {
    // H5Lexists fails, rather than saying false, when a group on the way is
    // missing, so every level is checked in turn.
    for (std::size_t slash = name.find('/', 1);; slash = name.find('/', slash + 1)) {
      const std::string prefix = name.substr(0, slash);
      if (!file_.nameExists(prefix)) fail("missing " + prefix);
      if (slash == std::string::npos) break;
    }
    if (file_.childObjType(name) != H5O_TYPE_DATASET) fail(name + " is not a dataset");
    return file_.openDataSet(name);
  }

  std::filesystem::path path_;
  H5::H5File file_;
  mutable std::size_t unchecked_ = 0;
};

template <class History>
std::vector<History> readHistory(const Reader& in, const HistoryLayout<History>& layout) {
  const std::string group = "/" + std::string(layout.group) + "/";
  const auto first = in.array<std::uint32_t>(group + layout.first_name);
  const auto second = in.array<std::uint32_t>(group + layout.second_name);
  const auto shear = in.array<Vec3>(group + "shear");
  if (second.size() != first.size() || shear.size() != first.size()) {
    in.fail("inconsistent array sizes in " + group + ": " + layout.first_name + " " +
            std::to_string(first.size()) + ", " + layout.second_name + " " +
            std::to_string(second.size()) + ", shear " + std::to_string(shear.size()));
  }
  std::vector<History> rows(first.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    rows[k].*layout.first = first[k];
    rows[k].*layout.second = second[k];
    rows[k].shear = shear[k];
  }
  if (in.has(group + "relax_offset")) {
    const auto offset = in.array<double>(group + "relax_offset");
    if (offset.size() != first.size()) in.fail("inconsistent array sizes in " + group + ": relax_offset");
    for (std::size_t k = 0; k < rows.size(); ++k) rows[k].relax_offset = offset[k];
  }
  return rows;
}

/// writeWallSlots' arrays; a file without them (no mesh wall, or written before
/// mesh walls had slots) has every contact in slot 0 with no normal.
void readWallSlots(const Reader& in, std::vector<WallHistory>& rows) {
  const std::string group = "/" + std::string(kWallLayout.group) + "/";
  if (!in.has(group + "slot")) return;
  const auto slot = in.array<std::uint32_t>(group + "slot");
  const auto normal = in.array<Vec3>(group + "normal");
  if (slot.size() != rows.size() || normal.size() != rows.size())
    in.fail("inconsistent array sizes in " + group + ": slot " + std::to_string(slot.size()) + ", normal " +
            std::to_string(normal.size()) + " (allowed: " + std::to_string(rows.size()) + ", one per row)");
  for (std::size_t k = 0; k < rows.size(); ++k) {
    rows[k].slot = slot[k];
    rows[k].normal = normal[k];
  }
}

ParticleState readParticles(const Reader& in) {
  ParticleState p;
#define ROCKLAB_READ(type, name, unit, meaning) p.name = in.array<type>("/particles/" #name);
  ROCKLAB_BALL_FIELDS(ROCKLAB_READ)
#undef ROCKLAB_READ
  if (!in.has("/clumps")) return p;  // a sphere-only run
  p.clump = in.array<std::int32_t>("/particles/clump");
  ClumpState& k = p.clumps;
#define ROCKLAB_READ(type, name, unit, meaning) k.name = in.array<type>("/clumps/" #name);
  ROCKLAB_CLUMP_FIELDS(ROCKLAB_READ)
#undef ROCKLAB_READ
  k.member_begin = in.array<std::uint32_t>("/clumps/member_begin");
  k.member_ball = in.array<std::uint32_t>("/clumps/member_ball");
  k.member_offset = in.array<Vec3>("/clumps/member_offset");
  return p;
}

/// Bond fields that came with contact bonds (§8.1): files written before them
/// hold parallel bonds only, which these fields' zeros describe.
bool addedWithContactBonds(const std::string& name) {
  return name == "kind" || name == "spring_normal" || name == "spring_shear" || name == "reference_overlap";
}

BondState readBonds(const Reader& in) {
  BondState b;
  if (!in.has("/bonds")) return b;  // a run without bonds
  const std::size_t n = in.array<std::uint32_t>("/bonds/a").size();
#define ROCKLAB_READ(type, name, unit, meaning)                                    \
  b.name = !in.has("/bonds/" #name) && addedWithContactBonds(#name) ? std::vector<type>(n) \
                                                                     : in.array<type>("/bonds/" #name);
  ROCKLAB_BOND_FIELDS(ROCKLAB_READ)
#undef ROCKLAB_READ
  return b;
}

Checkpoint readFile(const Reader& in) {
  in.checkFormat();
  Checkpoint checkpoint;
  checkpoint.scene_text = in.text("/scene");
  WorldState& state = checkpoint.state;
  state.time = in.attribute<double>("time");
  state.step = in.attribute<std::uint64_t>("step");
  state.dt = in.attribute<double>("dt");
  const int half_kick = in.attribute<int>("half_kick_pending");
  if (half_kick != 0 && half_kick != 1)
    in.fail("attribute half_kick_pending: " + std::to_string(half_kick) + " (allowed: 0, 1)");
  state.half_kick_pending = half_kick == 1;
  in.verifyRunScalars({state.time, state.step, state.dt, half_kick});
  state.particles = readParticles(in);
  state.pair_history = readHistory(in, kPairLayout);
  state.wall_history = readHistory(in, kWallLayout);
  readWallSlots(in, state.wall_history);
  state.bonds = readBonds(in);
  if (in.has("/moving_wall_work")) {
    const auto work = in.array<double>("/moving_wall_work");
    if (work.size() != 1) in.fail("dataset /moving_wall_work holds " + std::to_string(work.size()) + " values (expected 1)");
    if (!std::isfinite(work[0]))
      in.fail("dataset /moving_wall_work: " + std::to_string(work[0]) + " J (allowed: a finite number)");
    state.moving_wall_work = work[0];
  }
  if (in.has("/run_wall_time_s")) {
    const auto wall = in.array<double>("/run_wall_time_s");
    if (wall.size() != 1) in.fail("dataset /run_wall_time_s holds " + std::to_string(wall.size()) + " values (expected 1)");
    if (!(wall[0] >= 0) || !std::isfinite(wall[0]))
      in.fail("dataset /run_wall_time_s: " + std::to_string(wall[0]) + " s (allowed: a finite number >= 0)");
    checkpoint.run_wall_time_s = wall[0];
  }
  if (in.has("/experiment")) checkpoint.experiment_state = in.array<std::uint8_t>("/experiment");
  if (const std::string problem = inconsistency(state); !problem.empty()) in.fail(problem);
  checkpoint.unchecked = in.unchecked();
  return checkpoint;
}

}  // namespace

void writeCheckpoint(const std::filesystem::path& path, const WorldState& state,
                     const std::string& scene_text, std::span<const std::uint8_t> experiment_state,
                     double run_wall_time_s) {
  detail::recordHdf5Errors();  // errors reach the caller as exceptions, with the system's reason
  const std::string what = "cannot write checkpoint " + quoted(path) + ": ";
  if (const std::string problem = inconsistency(state); !problem.empty()) throw CheckpointError(what + problem);
  // A write that fails (a full disk) is an OutputError: the state was fine.
  const auto fail = [&](const std::string& reason) { return OutputError(what + reason); };

  std::string image;
  try {
    image = fileImage(path.string(), state, scene_text, experiment_state, run_wall_time_s);
  } catch (const H5::Exception& e) {
    throw fail(detail::hdf5Failure(e));
  }
  // Written beside the target and renamed over it, so an existing checkpoint is
  // replaced in one step and a crash never leaves a half-written one.
  std::error_code error;
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path(), error);
  writeFileAtomically(path, image);  // OutputError names the file and the reason
}

Checkpoint readCheckpoint(const std::filesystem::path& path) {
  H5::Exception::dontPrint();  // errors reach the caller as exceptions instead
  const auto fail = [&](const std::string& what) {
    return CheckpointError("checkpoint " + quoted(path) + ": " + what);
  };
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw fail("file does not exist");
  if (std::filesystem::is_directory(path, error)) throw fail("is a directory, not a checkpoint.h5");
  if (!std::filesystem::is_regular_file(path, error)) throw fail("not a regular file");
  try {
    if (!H5::H5File::isHdf5(path.string())) {
      throw fail("not a rocklab checkpoint (not an HDF5 file)");
    }
    return readFile(Reader(path));
  } catch (const H5::Exception& e) {
    throw fail(describe(e));
  }
}

}  // namespace rocklab::sim::output
