#include "rocklab/sim/output/run_file.h"

#include <H5Cpp.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <span>
#include <stdexcept>
#include <system_error>
#include <type_traits>
#include <utility>

#include "hdf5_io.h"
#include "rocklab/sim/output/file_write.h"
#include "snapshot_check.h"

namespace rocklab::sim::output {
namespace {

using detail::particleCount;
using detail::writeArray;
using detail::writeScalarAttribute;
using detail::writeText;
using detail::writeTextAttribute;

constexpr int kFormatVersion = 1;
constexpr hsize_t kEnergyColumns = 8;
// 256 rows x 8 doubles = 16 KiB per chunk: large enough for efficient I/O, small
// enough that a short run wastes little space.
constexpr hsize_t kEnergyChunkRows = 256;
constexpr const char* kEnergyColumnNames =
    "time [s], step [-], kinetic_translational [J], kinetic_rotational [J], "
    "potential_gravity [J], elastic [J], total [J], contacts [-]";
// The table mixes quantities, so its "unit" lists one unit per column.
constexpr const char* kEnergyUnits = "s, -, J, J, J, J, J, -";

void setIntAttribute(const H5::H5Object& object, const char* name, int value) {
  object.openAttribute(name).write(H5::PredType::NATIVE_INT, &value);
}

H5::DataSet createEnergyTable(const H5::Group& group) {
  const std::array<hsize_t, 2> dims{0, kEnergyColumns};
  const std::array<hsize_t, 2> max_dims{H5S_UNLIMITED, kEnergyColumns};
  const std::array<hsize_t, 2> chunk{kEnergyChunkRows, kEnergyColumns};
  H5::DSetCreatPropList properties;  // extendible datasets must be chunked
  properties.setChunk(2, chunk.data());
  const H5::DataSet table =
      group.createDataSet("energy", H5::PredType::NATIVE_DOUBLE,
                          H5::DataSpace(2, dims.data(), max_dims.data()), properties);
  writeTextAttribute(table, "unit", kEnergyUnits);
  writeTextAttribute(table, "columns", kEnergyColumnNames);
  return table;
}

/// Whether a frame holds a Snapshot array (its FrameWrite rule in ROCKLAB_SNAPSHOT_FIELDS).
bool framed(FrameWrite rule, bool empty, bool no_clumps) {
  switch (rule) {
    case FrameWrite::Always:
      return true;
    case FrameWrite::IfAny:
      return !empty;
    case FrameWrite::WithClumps:
      return !no_clumps;
    case FrameWrite::Never:
    case FrameWrite::PerFile:  // writeOncePerFile
      return false;
  }
  return false;
}

/// Every Snapshot array as owned storage (arrays a frame never holds stay empty).
struct SnapshotArrays {
#define ROCKLAB_STORAGE(type, name, index, unit, frame, meaning) std::vector<type> name;
  ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_STORAGE)
#undef ROCKLAB_STORAGE
};

constexpr const char* kPerFileGroup = "bonds";

/// A PerFile array (FrameWrite): the first non-empty values go to /bonds/<name>;
/// a later frame whose values differ from those (balls removed and the bonds
/// renumbered) carries its own copy. `written` holds what /bonds has.
template <class T>
void writeOncePerFile(const H5::Group& file, const H5::Group& frame, const char* name,
                      std::span<const T> values, const char* unit, std::vector<T>& written) {
  if (values.empty()) return;
  if (written.empty()) {
    const H5::Group group = file.nameExists(kPerFileGroup) ? file.openGroup(kPerFileGroup)
                                                           : file.createGroup(kPerFileGroup);
    writeArray(group, name, values, unit);
    written.assign(values.begin(), values.end());
  } else if (values.size() != written.size() ||
             std::memcmp(values.data(), written.data(), values.size() * sizeof(T)) != 0) {  // bitwise
    writeArray(frame, name, values, unit);
  }
}

// /materials: one group per row of the run's materials table (run_file.h).
constexpr const char* kMaterialsGroup = "materials";
constexpr std::size_t kMaterialProperties = 6;
constexpr const char* kMaterialColumnNames =
    "density [kg/m^3], kn [N/m], ks [N/m], friction [-], shear_modulus [Pa], poisson [-]";
constexpr const char* kMaterialUnits = "kg/m^3, N/m, N/m, -, Pa, -";

std::string materialGroupName(std::size_t row) {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu", row);
  return name;
}

/// "" or why the rows of `materials` past the `written` ones cannot be added.
std::string materialsProblem(std::span<const Material> materials, std::size_t written) {
  if (materials.empty()) return {};  // no table with this frame: nothing to add
  if (materials.size() < written)
    return "materials: the table has " + std::to_string(materials.size()) + " rows, /materials already holds " +
           std::to_string(written) + " (rows are only ever added)";
  for (std::size_t k = written; k < materials.size(); ++k)
    if (const int from = materials[k].made_from; from < -1 || from >= static_cast<int>(k))
      return "materials row " + std::to_string(k) + " ('" + materials[k].name + "'): made_from " +
             std::to_string(from) + " (allowed: -1 or an earlier row, 0 to " + std::to_string(k) + " - 1)";
  return {};
}

void writeMaterial(const H5::Group& file, std::size_t row, const Material& m) {
  const H5::Group table =
      file.nameExists(kMaterialsGroup) ? file.openGroup(kMaterialsGroup) : file.createGroup(kMaterialsGroup);
  const H5::Group group = table.createGroup(materialGroupName(row));
  writeText(group, "name", m.name);
  const std::array<double, kMaterialProperties> values{m.density, m.kn, m.ks, m.friction, m.shear_modulus, m.poisson};
  writeArray(group, "properties", std::span<const double>(values), kMaterialUnits);
  writeTextAttribute(group.openDataSet("properties"), "columns", kMaterialColumnNames);
  const std::array<std::int32_t, 1> from{m.made_from};
  writeArray(group, "made_from", std::span<const std::int32_t>(from), "-");
}

/// A scalar string dataset written by writeText, its checksum verified.
std::string readText(const H5::Group& group, const char* name) {
  if (!group.nameExists(name)) throw std::runtime_error(std::string("no dataset ") + name);
  const H5::DataSet dataset = group.openDataSet(name);
  if (dataset.getTypeClass() != H5T_STRING || dataset.getSpace().getSimpleExtentNpoints() != 1)
    throw std::runtime_error(std::string("dataset ") + name + " is not a single string");
  std::string text;
  dataset.read(text, dataset.getStrType());
  if (const auto c = detail::verifyChecksum(dataset, text.data(), text.size()); !c.matches)
    throw std::runtime_error(std::string("dataset ") + name + ": " + c.mismatch());
  return text;
}

/// /materials as stored; empty without it. Throws std::runtime_error naming the
/// row's group and what is wrong (a missing row, a bad shape, a made_from that is
/// not an earlier row, a value that is not a finite number).
std::vector<Material> readMaterials(const H5::H5File& file) {
  if (!file.nameExists(kMaterialsGroup)) return {};
  const H5::Group table = file.openGroup(kMaterialsGroup);
  std::vector<std::string> rows;
  for (hsize_t k = 0; k < table.getNumObjs(); ++k) rows.push_back(table.getObjnameByIdx(k));
  std::sort(rows.begin(), rows.end());
  std::vector<Material> materials;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const std::string where = "/" + std::string(kMaterialsGroup) + "/" + materialGroupName(k);
    if (rows[k] != materialGroupName(k))
      throw std::runtime_error(where + ": missing (the table has '" + rows[k] + "' in its place)");
    try {
      const H5::Group group = table.openGroup(rows[k]);
      Material m;
      m.name = readText(group, "name");
      const std::vector<double> values = detail::readArray<double>(group, "properties");
      if (values.size() != kMaterialProperties)
        throw std::runtime_error("dataset properties has " + std::to_string(values.size()) + " values (allowed: " +
                                 std::to_string(kMaterialProperties) + ")");
      for (const double v : values)
        if (!std::isfinite(v)) throw std::runtime_error("dataset properties: " + std::to_string(v) + " is not finite");
      m.density = values[0];
      m.kn = values[1];
      m.ks = values[2];
      m.friction = values[3];
      m.shear_modulus = values[4];
      m.poisson = values[5];
      const std::vector<std::int32_t> from = detail::readArray<std::int32_t>(group, "made_from");
      if (from.size() != 1)
        throw std::runtime_error("dataset made_from has " + std::to_string(from.size()) + " values (allowed: 1)");
      if (from[0] < -1 || from[0] >= static_cast<std::int32_t>(k))
        throw std::runtime_error("made_from: " + std::to_string(from[0]) + " (allowed: -1 or an earlier row, 0 to " +
                                 std::to_string(k) + " - 1)");
      m.made_from = from[0];
      materials.push_back(std::move(m));
    } catch (const H5::Exception& e) {
      throw std::runtime_error(where + ": " + e.getDetailMsg());
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(where + ": " + e.what());
    }
  }
  return materials;
}

std::string bondProblemText(const detail::ArrayProblem& p) {
  return std::string(p.array) + " row " + std::to_string(p.row) + ": " + p.what;
}

std::string frameGroupName(std::size_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frames/%06zu", frame);
  return name;
}

/// Runs an HDF5 action and turns its exception into one that names the file and
/// the system's reason ("no space left on device"); `failed` is set then.
template <class Action>
void guarded(const std::filesystem::path& file, const char* what, bool& failed, Action&& action) {
  detail::recordHdf5Errors();
  try {
    std::forward<Action>(action)();
  } catch (const H5::Exception& e) {
    failed = true;
    throw OutputError("run file '" + file.string() + "': cannot " + what + ": " + detail::hdf5Failure(e));
  }
}

/// The same for a RunFile: also fails when an HDF5 failure elsewhere diverted
/// the file to memory (detail::watchForFailure), so no write is lost unseen.
template <class Impl, class Action>
void guardedWrite(Impl& impl, const char* what, Action&& action) {
  if (const std::string reason = impl.handle.failure(); !impl.failed && !reason.empty()) {
    impl.failed = true;  // a close HDF5 does in a destructor failed, unseen until now
    throw OutputError("run file '" + impl.partial.string() + "': cannot " + what + ": " + reason +
                      " (an earlier write to it failed)");
  }
  guarded(impl.partial, what, impl.failed, std::forward<Action>(action));
}

}  // namespace

struct RunFile::Impl {
  Impl(std::filesystem::path final_path, std::filesystem::path partial_path,
       const std::string& scene_text)
      : path(std::move(final_path)), partial(std::move(partial_path)), handle(partial.string(), false) {
    const H5::Group& file = handle.root();
    writeTextAttribute(file, "format", "rocklab-run");
    writeScalarAttribute(file, "version", H5::PredType::NATIVE_INT, kFormatVersion);
    // Both stay 0 until close(): a .partial left by a killed run reads as neither.
    writeScalarAttribute(file, "complete", H5::PredType::NATIVE_INT, 0);
    writeScalarAttribute(file, "interrupted", H5::PredType::NATIVE_INT, 0);
    writeText(file, "scene", scene_text);
    file.createGroup("frames");
    energy = createEnergyTable(file);
    handle.flush();
  }
  const H5::Group& file() const { return handle.root(); }

  void requireOpen(const char* operation) const {
    if (!open) throw std::logic_error("RunFile::" + std::string(operation) + " after close()");
  }

  std::filesystem::path path;     // the finished file, created by close()
  std::filesystem::path partial;  // `<path>.partial`, written while the run goes on
  detail::FileHandle handle;  // closed once (a full disk must not crash a second close)
  H5::DataSet energy;
  SnapshotArrays per_file;  // what /bonds holds (PerFile arrays), empty until written
  std::size_t materials = 0;  // rows in /materials
  hsize_t energy_rows = 0;
  std::size_t frames = 0;
  bool open = true;
  bool failed = false;  // a write failed: the file cannot be finished (discard())
};

RunFile::RunFile(const std::filesystem::path& path, const std::string& scene_text) {
  std::filesystem::path partial = path;
  partial += ".partial";
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  bool failed = false;
  try {
    guarded(partial, "create it", failed, [&] { impl_ = std::make_unique<Impl>(path, partial, scene_text); });
  } catch (const OutputError&) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);  // nothing in it yet
    throw;
  }
}

RunFile::~RunFile() {
  if (!impl_ || !impl_->open) return;
  if (failed()) {
    discard();  // a file a write failed in is not a trajectory (the owner should have said so)
    return;
  }
  try {
    impl_->handle.close();  // the .partial stays: it holds every frame flushed so far
  } catch (const H5::Exception&) {
    // A destructor must not throw; the frames already flushed remain readable.
  }
}

bool RunFile::failed() const {
  return impl_->failed || !impl_->handle.failure().empty();
}

void RunFile::discard() noexcept {
  if (!impl_->open) return;
  impl_->open = false;
  impl_->handle.abandon();
  std::error_code ignored;
  std::filesystem::remove(impl_->partial, ignored);
}

void RunFile::writeFrame(const Snapshot& snapshot, std::span<const Material> materials) {
  impl_->requireOpen("writeFrame");
  // The arrays are checked before anything is written.
  if (const auto bad = detail::bondProblem(snapshot, particleCount(snapshot)))
    throw std::invalid_argument("snapshot: " + bondProblemText(*bad));
  if (const std::string bad = materialsProblem(materials, impl_->materials); !bad.empty())
    throw std::invalid_argument(bad);
  guardedWrite(*impl_, "write a frame", [&] {
    // The new materials first: a frame is never on disk without the rows it uses.
    for (; impl_->materials < materials.size(); ++impl_->materials)
      writeMaterial(impl_->file(), impl_->materials, materials[impl_->materials]);
    const H5::Group frame = impl_->file().createGroup(frameGroupName(impl_->frames));
    writeScalarAttribute(frame, "time", H5::PredType::NATIVE_DOUBLE, snapshot.time);
    writeScalarAttribute(frame, "step", H5::PredType::NATIVE_UINT64, snapshot.step);
#define ROCKLAB_WRITE(type, name, index, unit, frame_write, meaning)                          \
  if (FrameWrite::frame_write == FrameWrite::PerFile)                                         \
    writeOncePerFile(impl_->file(), frame, #name, snapshot.name, unit, impl_->per_file.name); \
  else if (framed(FrameWrite::frame_write, snapshot.name.empty(), snapshot.clump_id.empty())) \
    writeArray(frame, #name, snapshot.name, unit);
    ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_WRITE)
#undef ROCKLAB_WRITE
    // Flushing makes the frame (and the energy rows before it) survive a kill.
    impl_->handle.flush();
  });
  ++impl_->frames;
}

void RunFile::appendEnergy(const Snapshot& snapshot) {
  impl_->requireOpen("appendEnergy");
  const Energy& e = snapshot.energy;
  const std::array<double, kEnergyColumns> row{snapshot.time,
                                               static_cast<double>(snapshot.step),
                                               e.kinetic_translational,
                                               e.kinetic_rotational,
                                               e.potential_gravity,
                                               e.elastic,
                                               e.total(),
                                               static_cast<double>(snapshot.contacts)};
  // Not flushed here: rows may come every few steps; the next frame's flush
  // (or close) writes them out.
  guardedWrite(*impl_, "append an energy row", [&] {
    const hsize_t r = impl_->energy_rows;
    const std::array<hsize_t, 2> grown{r + 1, kEnergyColumns};
    impl_->energy.extend(grown.data());
    const std::array<hsize_t, 2> start{r, 0};
    const std::array<hsize_t, 2> count{1, kEnergyColumns};
    H5::DataSpace file_space = impl_->energy.getSpace();
    file_space.selectHyperslab(H5S_SELECT_SET, count.data(), start.data());
    const H5::DataSpace memory_space(2, count.data());
    impl_->energy.write(row.data(), H5::PredType::NATIVE_DOUBLE, memory_space, file_space);
  });
  ++impl_->energy_rows;
}

std::size_t RunFile::frameCount() const {
  return impl_->frames;
}

void RunFile::close(bool interrupted) {
  impl_->requireOpen("close");
  if (impl_->failed) throw std::logic_error("RunFile::close after a failed write (discard() it)");
  try {
    guardedWrite(*impl_, "finish it", [&] {
      setIntAttribute(impl_->file(), "complete", interrupted ? 0 : 1);
      setIntAttribute(impl_->file(), "interrupted", interrupted ? 1 : 0);
      impl_->handle.close();
    });
  } catch (const OutputError&) {
    discard();  // the close failed (a full disk): the handle is abandoned, the .partial removed
    throw;
  }
  impl_->open = false;
  // rename() replaces an existing run file in one step: readers see the old
  // file or the new one, never a mixture.
  std::error_code error;
  std::filesystem::rename(impl_->partial, impl_->path, error);
  if (error) {
    std::error_code ignored;
    std::filesystem::remove(impl_->partial, ignored);
    throw OutputError("run file: cannot rename '" + impl_->partial.string() + "' to '" + impl_->path.string() +
                      "': " + systemReason(error.value()));
  }
}

}  // namespace rocklab::sim::output

namespace rocklab::sim::output {

struct RunFileReader::Impl {
  std::filesystem::path path;
  H5::H5File file;
  std::string scene;
  std::vector<Material> materials;  // /materials, empty without it
  std::vector<std::string> frame_names;
  SnapshotArrays current;   // the current frame's arrays
  SnapshotArrays per_file;  // /bonds: the PerFile arrays of the frames that do not carry their own
  Snapshot snapshot;
};

RunFileReader::RunFileReader(const std::filesystem::path& path) : impl_(std::make_unique<Impl>()) {
  H5::Exception::dontPrint();
  impl_->path = path;
  const std::string where = "run file '" + path.string() + "': ";
  try {
    if (!std::filesystem::exists(path)) throw std::runtime_error(where + "does not exist");
    if (std::filesystem::is_directory(path)) throw std::runtime_error(where + "is a directory, not a run.h5");
    if (!H5::H5File::isHdf5(path.string())) throw std::runtime_error(where + "not an HDF5 file");
    impl_->file = H5::H5File(path.string(), H5F_ACC_RDONLY);
    if (!impl_->file.nameExists("scene") || !impl_->file.nameExists("frames"))
      throw std::runtime_error(where + "not a rocklab run file (no /scene or /frames)");
    const H5::DataSet scene = impl_->file.openDataSet("scene");
    if (scene.getTypeClass() != H5T_STRING || scene.getSpace().getSimpleExtentNpoints() != 1)
      throw std::runtime_error(where + "dataset /scene is not a single string");
    scene.read(impl_->scene, scene.getStrType());
    if (const auto c = detail::verifyChecksum(scene, impl_->scene.data(), impl_->scene.size()); !c.matches)
      throw std::runtime_error(where + "dataset /scene: " + c.mismatch());
    impl_->materials = readMaterials(impl_->file);
    const H5::Group frames = impl_->file.openGroup("frames");
    for (hsize_t k = 0; k < frames.getNumObjs(); ++k) impl_->frame_names.push_back(frames.getObjnameByIdx(k));
    std::sort(impl_->frame_names.begin(), impl_->frame_names.end());  // 000000, 000001, ...
    if (impl_->file.nameExists(kPerFileGroup)) {
      const H5::Group group = impl_->file.openGroup(kPerFileGroup);
#define ROCKLAB_READ_PER_FILE(type, name, index, unit, frame, meaning) \
  if (FrameWrite::frame == FrameWrite::PerFile) impl_->per_file.name = detail::readArray<type>(group, #name);
      ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_READ_PER_FILE)
#undef ROCKLAB_READ_PER_FILE
    }
  } catch (const H5::Exception& e) {
    throw std::runtime_error(where + e.getDetailMsg());
  } catch (const std::runtime_error& e) {
    if (std::string(e.what()).starts_with(where)) throw;
    throw std::runtime_error(where + e.what());  // a /bonds dataset of the wrong shape
  }
}

RunFileReader::~RunFileReader() = default;

const std::string& RunFileReader::sceneText() const { return impl_->scene; }
const std::vector<Material>& RunFileReader::materials() const { return impl_->materials; }
std::size_t RunFileReader::frameCount() const { return impl_->frame_names.size(); }

const Snapshot& RunFileReader::frame(std::size_t k) {
  Impl& m = *impl_;
  SnapshotArrays& c = m.current;
  using detail::readArray;
  try {
    const std::string group = "frames/" + m.frame_names.at(k);
    const H5::Group g = m.file.openGroup(group);
    Snapshot& s = m.snapshot;
    s = Snapshot{};
    s.time = detail::readScalarAttribute<double>(g, "time", H5::PredType::NATIVE_DOUBLE);
    s.step = detail::readScalarAttribute<std::uint64_t>(g, "step", H5::PredType::NATIVE_UINT64);
    if (!std::isfinite(s.time) || s.time < 0)
      throw std::runtime_error("attribute time of /" + group + ": " + std::to_string(s.time) +
                               " s (allowed: >= 0 s, finite)");
    // A PerFile array comes from the frame when it carries its own, else from
    // /bonds, and only in a frame that holds bonds (bond_intact).
#define ROCKLAB_READ(type, name, index, unit, frame, meaning) \
  if (FrameWrite::frame != FrameWrite::Never) c.name = readArray<type>(g, #name);
    ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_READ)
#undef ROCKLAB_READ
#define ROCKLAB_FROM_FILE(type, name, index, unit, frame, meaning)                               \
  if (FrameWrite::frame == FrameWrite::PerFile && c.name.empty() && !c.bond_intact.empty()) \
    c.name = m.per_file.name;
    ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_FROM_FILE)
#undef ROCKLAB_FROM_FILE
#define ROCKLAB_VIEW(type, name, index, unit, frame, meaning) s.name = c.name;
    ROCKLAB_SNAPSHOT_FIELDS(ROCKLAB_VIEW)
#undef ROCKLAB_VIEW
    // Every size, index and number before anyone indexes with them (a renderer
    // would read past an array).
    if (const auto bad = detail::frameProblem(s)) {
      // Name the dataset the rows came from: the frame's own or the file's /bonds.
      const std::string per_file = std::string(kPerFileGroup) + "/" + bad->array;
      const bool from_file = !g.nameExists(bad->array) && m.file.nameExists(kPerFileGroup) &&
                             m.file.openGroup(kPerFileGroup).nameExists(bad->array);
      const std::string dataset = from_file ? per_file : group + "/" + bad->array;
      throw std::runtime_error("dataset /" + dataset + " row " + std::to_string(bad->row) + ": " + bad->what);
    }
    if (c.material.empty()) {  // files from before materials were stored
      c.material.assign(c.position.size(), 0);
      s.material = c.material;
    }
    return s;
  } catch (const H5::Exception& e) {
    throw std::runtime_error("run file '" + m.path.string() + "' frame " + std::to_string(k) + ": " + e.getDetailMsg());
  } catch (const std::exception& e) {  // a bad shape, length or bond row
    throw std::runtime_error("run file '" + m.path.string() + "' frame " + std::to_string(k) + ": " + e.what());
  }
}

}  // namespace rocklab::sim::output
