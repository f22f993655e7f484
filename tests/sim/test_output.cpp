// Output modules: run file (HDF5), ParaView series (.vtp + .pvd), checkpoint.
#include <H5Cpp.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <array>
#include <bit>
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <random>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "rocklab/sim/output/checkpoint.h"
#include "rocklab/sim/output/run_file.h"
#include "rocklab/geometry/frustum_mesh.h"
#include "rocklab/sim/output/vtk_series.h"
#include "rocklab/sim/wall_motion.h"

namespace {

namespace fs = std::filesystem;
using rocklab::sim::Snapshot;
using rocklab::sim::Vec3;
using rocklab::sim::WorldState;
namespace output = rocklab::sim::output;

/// A fresh directory under the system temp directory, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    std::random_device random;
    do {
      path_ = fs::temp_directory_path() /
              ("rocklab-test-output-" + std::to_string(random()) + std::to_string(random()));
    } while (!fs::create_directory(path_));  // false: the name is taken, draw again
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  fs::path operator/(const std::string& name) const { return path_ / name; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// Owns the arrays a Snapshot points into; values differ per particle and frame.
struct Frame {
  Frame(std::size_t n, double t, std::uint64_t s) : time(t), step(s) {
    for (std::size_t k = 0; k < n; ++k) {
      const double x = static_cast<double>(k) + t;
      position.emplace_back(0.1 * x, -0.3 * x, 1.0 / (x + 3.0));  // m
      velocity.emplace_back(x / 7.0, 2.5, -x);                    // m/s
      omega.emplace_back(-1.0 / (x + 1.0), 0.0, 10.0 * x);        // rad/s
      force.emplace_back(0.0, 0.0, -9.81 * (x + 1.0));            // N
      radius.push_back(0.01 + 0.001 * x);                         // m
      id.push_back(1000 + k);
    }
  }
  Snapshot snapshot() const {
    Snapshot s;
    s.time = time;
    s.step = step;
    s.position = position;
    s.velocity = velocity;
    s.omega = omega;
    s.force = force;
    s.radius = radius;
    s.id = id;
    s.bond_a = bond_a;
    s.bond_b = bond_b;
    s.bond_intact = bond_intact;
    s.energy = {1.5 + time, 0.25, -3.0 * time, 0.125};
    s.contacts = 7;
    return s;
  }
  double time;         // s
  std::uint64_t step;  // -
  std::vector<Vec3> position, velocity, omega, force;
  std::vector<double> radius;
  std::vector<std::uint64_t> id;
  std::vector<std::uint32_t> bond_a, bond_b;  // empty: a world without bonds
  std::vector<std::uint8_t> bond_intact;
};

fs::path partialOf(const fs::path& path) {
  fs::path partial = path;
  partial += ".partial";
  return partial;
}

std::string fileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// ---- HDF5 read helpers (independent of the implementation under test)

std::string stringAttribute(const H5::H5Object& object, const char* name) {
  const H5::Attribute attribute = object.openAttribute(name);
  std::string value;
  attribute.read(attribute.getStrType(), value);
  return value;
}

template <class T>
T scalarAttribute(const H5::H5Object& object, const char* name, const H5::PredType& type) {
  T value{};
  object.openAttribute(name).read(type, &value);
  return value;
}

std::vector<hsize_t> shapeOf(const H5::DataSet& dataset) {
  const H5::DataSpace space = dataset.getSpace();
  std::vector<hsize_t> dims(static_cast<std::size_t>(space.getSimpleExtentNdims()));
  space.getSimpleExtentDims(dims.data());
  return dims;
}

std::vector<Vec3> readVec3s(const H5::Group& group, const char* name) {
  const H5::DataSet dataset = group.openDataSet(name);
  const auto shape = shapeOf(dataset);
  REQUIRE(shape.size() == 2);
  REQUIRE(shape[1] == 3);
  std::vector<Vec3> values(shape[0]);
  if (!values.empty()) dataset.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  return values;
}

template <class T>
std::vector<T> readValues(const H5::Group& group, const char* name, const H5::PredType& type) {
  const H5::DataSet dataset = group.openDataSet(name);
  const auto shape = shapeOf(dataset);
  REQUIRE(shape.size() == 1);
  std::vector<T> values(shape[0]);
  if (!values.empty()) dataset.read(values.data(), type);
  return values;
}

std::string readText(const H5::Group& group, const char* name) {
  const H5::DataSet dataset = group.openDataSet(name);
  std::string text;
  dataset.read(text, dataset.getStrType());
  return text;
}

/// Checks one frame group against the frame it was written from.
void checkFrame(const H5::Group& group, const Frame& frame) {
  CHECK(scalarAttribute<double>(group, "time", H5::PredType::NATIVE_DOUBLE) == frame.time);
  CHECK(scalarAttribute<std::uint64_t>(group, "step", H5::PredType::NATIVE_UINT64) == frame.step);
  CHECK(readVec3s(group, "position") == frame.position);
  CHECK(readVec3s(group, "velocity") == frame.velocity);
  CHECK(readVec3s(group, "omega") == frame.omega);
  CHECK(readVec3s(group, "force") == frame.force);
  CHECK(readValues<double>(group, "radius", H5::PredType::NATIVE_DOUBLE) == frame.radius);
  CHECK(readValues<std::uint64_t>(group, "id", H5::PredType::NATIVE_UINT64) == frame.id);
  const std::array<std::pair<const char*, const char*>, 6> units{{{"position", "m"},
                                                                  {"velocity", "m/s"},
                                                                  {"omega", "rad/s"},
                                                                  {"force", "N"},
                                                                  {"radius", "m"},
                                                                  {"id", ""}}};
  for (const auto& [name, unit] : units) {
    INFO("dataset " << name);
    CHECK(stringAttribute(group.openDataSet(name), "unit") == unit);
  }
}

const std::string kScene = "# drop test – ünïcode survives\n[[spheres]]\nradius = 0.01\n";

}  // namespace

TEST_CASE("output: run file layout round trip", "[output]") {
  H5::Exception::dontPrint();
  TempDir dir;
  const fs::path path = dir / "run.h5";
  const std::vector<Frame> frames{{4, 0.0, 0}, {4, 0.01, 100}, {4, 0.02, 200}};
  {
    output::RunFile run(path, kScene);
    for (const Frame& frame : frames) {
      run.writeFrame(frame.snapshot());
      run.appendEnergy(frame.snapshot());
    }
    run.appendEnergy(frames.back().snapshot());  // energy rows need not match frames
    CHECK(run.frameCount() == 3);
    run.close(false);
  }
  REQUIRE(fs::exists(path));
  CHECK_FALSE(fs::exists(partialOf(path)));

  const H5::H5File file(path.string(), H5F_ACC_RDONLY);
  CHECK(stringAttribute(file, "format") == "rocklab-run");
  CHECK(scalarAttribute<int>(file, "version", H5::PredType::NATIVE_INT) == 1);
  CHECK(scalarAttribute<int>(file, "complete", H5::PredType::NATIVE_INT) == 1);
  CHECK(scalarAttribute<int>(file, "interrupted", H5::PredType::NATIVE_INT) == 0);
  CHECK(readText(file, "scene") == kScene);
  CHECK(stringAttribute(file.openDataSet("scene"), "unit").empty());

  const H5::Group frames_group = file.openGroup("frames");
  REQUIRE(frames_group.getNumObjs() == 3);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const std::string name = "00000" + std::to_string(k);
    INFO("frame " << name);
    CHECK(frames_group.getObjnameByIdx(k) == name);
    checkFrame(frames_group.openGroup(name), frames[k]);
  }

  const H5::DataSet energy = file.openDataSet("energy");
  std::array<hsize_t, 2> dims{}, max_dims{};
  energy.getSpace().getSimpleExtentDims(dims.data(), max_dims.data());
  CHECK(dims == std::array<hsize_t, 2>{4, 8});
  CHECK(max_dims[0] == H5S_UNLIMITED);
  CHECK(energy.getCreatePlist().getLayout() == H5D_CHUNKED);
  CHECK(stringAttribute(energy, "columns")
            .starts_with("time [s], step [-], kinetic_translational [J]"));
  CHECK(stringAttribute(energy, "unit") == "s, -, J, J, J, J, J, -");
  std::vector<double> rows(4 * 8);
  energy.read(rows.data(), H5::PredType::NATIVE_DOUBLE);
  const Snapshot second = frames[1].snapshot();
  const std::vector<double> expected{second.time,
                                     static_cast<double>(second.step),
                                     second.energy.kinetic_translational,
                                     second.energy.kinetic_rotational,
                                     second.energy.potential_gravity,
                                     second.energy.elastic,
                                     second.energy.total(),
                                     static_cast<double>(second.contacts)};
  CHECK(std::vector<double>(rows.begin() + 8, rows.begin() + 16) == expected);
}

TEST_CASE("output: run file replaces the old file only on close", "[output]") {
  H5::Exception::dontPrint();
  TempDir dir;
  const fs::path path = dir / "run.h5";
  {
    output::RunFile old_run(path, "old scene");
    old_run.writeFrame(Frame(2, 0.0, 0).snapshot());
    old_run.close(false);
  }
  const std::string old_bytes = fileBytes(path);
  REQUIRE_FALSE(old_bytes.empty());

  output::RunFile new_run(path, "new scene");
  new_run.writeFrame(Frame(3, 0.0, 0).snapshot());
  new_run.writeFrame(Frame(3, 0.5, 50).snapshot());
  CHECK(fileBytes(path) == old_bytes);  // the good file is untouched while the new one grows
  CHECK(fs::exists(partialOf(path)));

  new_run.close(true);
  CHECK_FALSE(fs::exists(partialOf(path)));
  const H5::H5File file(path.string(), H5F_ACC_RDONLY);
  CHECK(readText(file, "scene") == "new scene");
  CHECK(file.openGroup("frames").getNumObjs() == 2);
  CHECK(scalarAttribute<int>(file, "complete", H5::PredType::NATIVE_INT) == 0);
  CHECK(scalarAttribute<int>(file, "interrupted", H5::PredType::NATIVE_INT) == 1);
}

TEST_CASE("output: run file destructor without close keeps a readable .partial", "[output]") {
  H5::Exception::dontPrint();
  TempDir dir;
  const fs::path path = dir / "run.h5";
  const std::vector<Frame> frames{{3, 0.0, 0}, {3, 0.1, 10}};
  {
    output::RunFile run(path, kScene);
    for (const Frame& frame : frames) {
      run.writeFrame(frame.snapshot());
      run.appendEnergy(frame.snapshot());
    }
  }  // no close(): as when a run dies with an exception
  CHECK_FALSE(fs::exists(path));
  REQUIRE(fs::exists(partialOf(path)));

  const H5::H5File file(partialOf(path).string(), H5F_ACC_RDONLY);
  CHECK(scalarAttribute<int>(file, "complete", H5::PredType::NATIVE_INT) == 0);
  CHECK(scalarAttribute<int>(file, "interrupted", H5::PredType::NATIVE_INT) == 0);
  CHECK(readText(file, "scene") == kScene);
  REQUIRE(file.openGroup("frames").getNumObjs() == 2);
  checkFrame(file.openGroup("frames/000001"), frames[1]);
  CHECK(shapeOf(file.openDataSet("energy"))[0] == 2);
}

TEST_CASE("output: run file with no particles", "[output]") {
  H5::Exception::dontPrint();
  TempDir dir;
  const fs::path path = dir / "empty.h5";
  const Frame empty(0, 0.0, 0);
  {
    output::RunFile run(path, "");
    run.writeFrame(empty.snapshot());
    run.appendEnergy(empty.snapshot());
    run.close(false);
  }
  const H5::H5File file(path.string(), H5F_ACC_RDONLY);
  const H5::Group frame = file.openGroup("frames/000000");
  CHECK(shapeOf(frame.openDataSet("position")) == std::vector<hsize_t>{0, 3});
  CHECK(shapeOf(frame.openDataSet("radius")) == std::vector<hsize_t>{0});
  checkFrame(frame, empty);
  CHECK(readText(file, "scene").empty());
}

TEST_CASE("output: run file rejects snapshots whose arrays differ in length", "[output]") {
  TempDir dir;
  output::RunFile run(dir / "run.h5", "");
  Frame frame(3, 0.0, 0);
  frame.radius.pop_back();
  CHECK_THROWS_AS(run.writeFrame(frame.snapshot()), std::invalid_argument);
  CHECK(run.frameCount() == 0);
}

TEST_CASE("output: run file bond state: ends once per file, intact flags per frame", "[output][bonds]") {
  H5::Exception::dontPrint();
  TempDir dir;
  const fs::path path = dir / "run.h5";
  Frame first(3, 0.0, 0), broken(3, 0.1, 10), renumbered(2, 0.2, 20), unbonded(2, 0.3, 30);
  first.bond_a = broken.bond_a = {0, 1};
  first.bond_b = broken.bond_b = {1, 2};
  first.bond_intact = {1, 1};
  broken.bond_intact = {1, 0};
  renumbered.bond_a = {0};  // ball 2 removed: one bond left, its ends new to the file
  renumbered.bond_b = {1};
  renumbered.bond_intact = {1};
  {
    output::RunFile run(path, kScene);
    for (const Frame* f : {&first, &broken, &renumbered, &unbonded}) run.writeFrame(f->snapshot());
    run.close(false);
  }
  {
    const H5::H5File file(path.string(), H5F_ACC_RDONLY);
    CHECK(readValues<std::uint32_t>(file.openGroup("bonds"), "bond_a", H5::PredType::NATIVE_UINT32) == first.bond_a);
    CHECK(readValues<std::uint32_t>(file.openGroup("bonds"), "bond_b", H5::PredType::NATIVE_UINT32) == first.bond_b);
    const H5::Group f1 = file.openGroup("frames/000001");
    CHECK(readValues<std::uint8_t>(f1, "bond_intact", H5::PredType::NATIVE_UINT8) == broken.bond_intact);
    CHECK_FALSE(f1.nameExists("bond_a"));  // the file's ends hold
    CHECK(file.openGroup("frames/000002").nameExists("bond_a"));  // its own, renumbered
    CHECK(file.openGroup("frames/000003").getNumObjs() == 6);    // no bond dataset at all
  }
  output::RunFileReader reader(path);
  REQUIRE(reader.frameCount() == 4);
  auto vec = []<class T>(std::span<const T> s) { return std::vector<T>(s.begin(), s.end()); };
  const std::array<const Frame*, 4> written{&first, &broken, &renumbered, &unbonded};
  for (std::size_t k = 0; k < written.size(); ++k) {
    INFO("frame " << k);
    const Frame* f = written[k];
    const Snapshot& s = reader.frame(k);
    CHECK(vec(s.bond_a) == f->bond_a);
    CHECK(vec(s.bond_b) == f->bond_b);
    CHECK(vec(s.bond_intact) == f->bond_intact);
  }
}

TEST_CASE("output: run file without bonds has no bond datasets", "[output][bonds]") {
  H5::Exception::dontPrint();
  TempDir dir;
  {
    output::RunFile run(dir / "run.h5", kScene);
    run.writeFrame(Frame(3, 0.0, 0).snapshot());
    run.close(false);
  }
  const H5::H5File file((dir / "run.h5").string(), H5F_ACC_RDONLY);
  CHECK_FALSE(file.nameExists("bonds"));
  const H5::Group frame = file.openGroup("frames/000000");
  std::set<std::string> names;
  for (hsize_t k = 0; k < frame.getNumObjs(); ++k) names.insert(frame.getObjnameByIdx(k));
  CHECK(names == std::set<std::string>{"force", "id", "omega", "position", "radius", "velocity"});
}

TEST_CASE("output: bad bond datasets in a run file are refused with file, dataset and row",
          "[output][bonds]") {
  H5::Exception::dontPrint();
  TempDir dir;
  const fs::path path = dir / "run.h5";
  Frame frame(3, 0.0, 0);
  frame.bond_a = {0, 1};
  frame.bond_b = {1, 2};
  frame.bond_intact = {1, 1};
  auto written = [&] {
    output::RunFile run(path, kScene);
    run.writeFrame(frame.snapshot());
    run.close(false);
  };
  // Replaces one dataset of the good file by `values` (as a tool or a bad copy might).
  auto replace = [&](const std::string& group, const char* name, const std::vector<std::uint32_t>& values) {
    written();
    H5::H5File file(path.string(), H5F_ACC_RDWR);
    const H5::Group g = file.openGroup(group);
    g.unlink(name);
    const hsize_t n = values.size();
    g.createDataSet(name, H5::PredType::NATIVE_UINT32, H5::DataSpace(1, &n))
        .write(values.data(), H5::PredType::NATIVE_UINT32);
  };
  auto error = [&] {
    try {
      output::RunFileReader reader(path);
      reader.frame(0);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  replace("bonds", "bond_b", {1, 7});
  std::string e = error();
  CHECK_THAT(e, Catch::Contains(path.string()) && Catch::Contains("dataset /bonds/bond_b row 1") &&
                    Catch::Contains("ball 7 does not exist (the frame has 3 balls)"));
  replace("bonds", "bond_a", {0});
  e = error();
  CHECK_THAT(e, Catch::Contains("dataset /bonds/bond_a row 1") && Catch::Contains("has 1 rows but bond_intact has 2"));
  replace("bonds", "bond_a", {0, 2});
  CHECK_THAT(error(), Catch::Contains("dataset /bonds/bond_b row 1: joins ball 2 to itself"));
  replace("frames/000000", "bond_intact", {1, 1, 0});  // uint32 read as uint8: values kept, length 3
  CHECK_THAT(error(), Catch::Contains("frame 0") && Catch::Contains("has 2 rows but bond_intact has 3"));
  // The writer refuses such a snapshot before writing anything.
  output::RunFile run(dir / "other.h5", kScene);
  frame.bond_b = {1, 3};
  CHECK_THROWS_WITH(run.writeFrame(frame.snapshot()), Catch::Contains("bond_b row 1: ball 3 does not exist"));
  CHECK(run.frameCount() == 0);
}

TEST_CASE("output: run file materials table: a frame's new rows go with it, a killed run's .partial keeps them",
          "[output][materials]") {
  H5::Exception::dontPrint();
  TempDir dir;
  const fs::path path = dir / "run.h5";
  // The scene's two materials, then a fragment class made from the first during the run.
  rocklab::sim::Material rock, steel, fragments;
  rock.name = "rock";
  rock.kn = 2e7;
  steel.name = "steel";
  steel.density = 7800.0;
  fragments = rock;
  fragments.name = "rock fragments 8-10 mm";
  fragments.kn = 1.25e6;
  fragments.shear_modulus = 3.5e9;
  fragments.made_from = 0;
  const std::vector<rocklab::sim::Material> scene{rock, steel}, grown{rock, steel, fragments};
  const std::vector<Frame> frames{{3, 0.0, 0}, {3, 0.1, 10}};
  {
    output::RunFile run(path, kScene);
    run.writeFrame(frames[0].snapshot(), scene);
    run.writeFrame(frames[1].snapshot(), grown);
  }  // no close(): as when a run dies with an exception
  REQUIRE(fs::exists(partialOf(path)));
  {
    const H5::H5File file(partialOf(path).string(), H5F_ACC_RDONLY);
    REQUIRE(file.openGroup("materials").getNumObjs() == 3);
    const H5::Group row = file.openGroup("materials/000002");
    CHECK(readText(row, "name") == "rock fragments 8-10 mm");
    CHECK(readValues<std::int32_t>(row, "made_from", H5::PredType::NATIVE_INT32) == std::vector<std::int32_t>{0});
    CHECK(stringAttribute(row.openDataSet("properties"), "unit") == "kg/m^3, N/m, N/m, -, Pa, -");
  }
  output::RunFileReader reader(partialOf(path));
  const auto& read = reader.materials();
  REQUIRE(read.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    INFO("row " << k);
    CHECK(read[k].name == grown[k].name);
    CHECK(read[k].density == grown[k].density);
    CHECK(read[k].kn == grown[k].kn);
    CHECK(read[k].ks == grown[k].ks);
    CHECK(read[k].friction == grown[k].friction);
    CHECK(read[k].shear_modulus == grown[k].shear_modulus);
    CHECK(read[k].poisson == grown[k].poisson);
    CHECK(read[k].made_from == grown[k].made_from);
  }
  CHECK(reader.frameCount() == 2);

  // A writer that passes no table (and every file from before it) has none.
  {
    output::RunFile run(dir / "plain.h5", kScene);
    run.writeFrame(frames[0].snapshot());
    run.close(false);
  }
  CHECK(output::RunFileReader(dir / "plain.h5").materials().empty());

  // Rows are only added, and made from an earlier row: refused before anything is written.
  output::RunFile run(dir / "other.h5", kScene);
  run.writeFrame(frames[0].snapshot(), grown);
  CHECK_THROWS_WITH(run.writeFrame(frames[1].snapshot(), scene), Catch::Contains("rows are only ever added"));
  auto looped = grown;
  looped.push_back(fragments);
  looped.back().made_from = 3;
  CHECK_THROWS_WITH(run.writeFrame(frames[1].snapshot(), looped),
                    Catch::Contains("materials row 3") && Catch::Contains("made_from 3"));
  CHECK(run.frameCount() == 1);
  run.close(false);

  // A damaged table is refused naming the file and the row.
  const fs::path damaged = dir / "damaged.h5";
  fs::copy_file(partialOf(path), damaged);
  auto error = [&] {
    try {
      output::RunFileReader bad(damaged);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  {
    H5::H5File file(damaged.string(), H5F_ACC_RDWR);
    const H5::Group row = file.openGroup("materials/000002");
    row.unlink("made_from");
    const std::int32_t bad = 2;
    const hsize_t n = 1;
    row.createDataSet("made_from", H5::PredType::NATIVE_INT32, H5::DataSpace(1, &n))
        .write(&bad, H5::PredType::NATIVE_INT32);
  }
  CHECK_THAT(error(), Catch::Contains(damaged.string()) && Catch::Contains("/materials/000002: made_from: 2") &&
                          Catch::Contains("an earlier row"));
  H5::H5File(damaged.string(), H5F_ACC_RDWR).openGroup("materials").unlink("000001");
  CHECK_THAT(error(), Catch::Contains("/materials/000001: missing"));
}

TEST_CASE("output: vtk series frames and collection", "[output]") {
  TempDir dir;
  const fs::path directory = dir / "paraview/drop";  // created by VtkSeries
  const std::vector<Frame> frames{{3, 0.0, 0}, {5, 0.25, 2500}};
  output::VtkSeries series(directory, "drop");
  for (const Frame& frame : frames) series.writeFrame(frame.snapshot());
  CHECK(series.frameCount() == 2);

  std::set<std::string> files;
  for (const auto& entry : fs::directory_iterator(directory)) {
    files.insert(entry.path().filename().string());
  }
  // Exactly the frames and the collection: no temporary file is left behind.
  CHECK(files == std::set<std::string>{"drop_000000.vtp", "drop_000001.vtp", "drop.pvd"});

  for (std::size_t f = 0; f < frames.size(); ++f) {
    const Frame& frame = frames[f];
    const fs::path file = directory / ("drop_00000" + std::to_string(f) + ".vtp");
    INFO(file);
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(file.c_str());
    reader->Update();
    vtkPolyData* poly = reader->GetOutput();
    const auto n = static_cast<vtkIdType>(frame.radius.size());
    REQUIRE(poly->GetNumberOfPoints() == n);
    CHECK(poly->GetNumberOfVerts() == n);

    vtkPointData* data = poly->GetPointData();
    REQUIRE(data->GetScalars() != nullptr);
    CHECK(std::string(data->GetScalars()->GetName()) == "radius");
    for (const char* name : {"velocity", "omega", "force"}) {
      INFO("array " << name);
      REQUIRE(data->GetArray(name) != nullptr);
      CHECK(data->GetArray(name)->GetNumberOfComponents() == 3);
    }
    vtkDataArray* ids = data->GetArray("id");
    REQUIRE(ids != nullptr);
    CHECK(ids->GetDataTypeSize() == 8);
    vtkDataArray* radius = data->GetArray("radius");
    vtkDataArray* velocity = data->GetArray("velocity");
    for (vtkIdType k = 0; k < n; ++k) {
      const auto i = static_cast<std::size_t>(k);
      CHECK(radius->GetComponent(k, 0) == frame.radius[i]);
      CHECK(static_cast<std::uint64_t>(ids->GetComponent(k, 0)) == frame.id[i]);
      CHECK(Vec3(Eigen::Map<const Vec3>(poly->GetPoint(k))) == frame.position[i]);
      CHECK(Vec3(Eigen::Map<const Vec3>(velocity->GetTuple3(k))) == frame.velocity[i]);
    }
  }

  const std::string pvd = fileBytes(directory / "drop.pvd");
  CHECK(pvd.find("<VTKFile type=\"Collection\" version=\"0.1\">") != std::string::npos);
  const std::regex dataset_entry(
      R"re(<DataSet timestep="([^"]*)" group="" part="0" file="([^"]*)"/>)re");
  std::vector<std::pair<double, std::string>> entries;
  for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), dataset_entry);
       it != std::sregex_iterator(); ++it) {
    entries.emplace_back(std::stod((*it)[1].str()), (*it)[2].str());
  }
  CHECK(entries == std::vector<std::pair<double, std::string>>{{0.0, "drop_000000.vtp"},
                                                               {0.25, "drop_000001.vtp"}});
}

namespace {

/// A state with awkward values: a round trip must keep every bit, NaN and -0 too.
WorldState awkwardState() {
  WorldState state;
  state.time = 0.1 + 0.2;  // s, not exactly 0.3
  state.step = (std::uint64_t{1} << 40) + 7;
  state.dt = 1e-6 / 3.0;  // s
  state.half_kick_pending = false;
  state.moving_wall_work = -1.0 / 3.0;  // J
  auto& p = state.particles;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double tiny = std::numeric_limits<double>::denorm_min();
  p.position = {{0.1, 0.2, 0.3}, {-0.0, 1.0 / 3.0, 1e300}, {tiny, -tiny, 2.0 / 7.0}};
  p.velocity = {{1.0 / 9.0, 0.0, -2.5}, {3.0, nan, 0.0}, {-1e-308, 5.0, 6.0}};
  p.omega = {{0.0, 0.0, 1.0 / 11.0}, {-7.0, 8.0, 9.0}, {10.0, -0.0, 0.125}};
  p.radius = {0.01, 0.011, 1.0 / 300.0};
  p.mass = {0.0113, 0.015, 1.0 / 3.0};
  p.inv_mass = {1.0 / 0.0113, 1.0 / 0.015, 3.0};
  p.inv_inertia = {1.0 / 3.1e-7, 0.0, 1.0 / 7e-9};
  p.material = {0, 2, -1};
  p.id = {0, 42, std::numeric_limits<std::uint64_t>::max()};
  state.pair_history = {{0, 1, {0.5, -0.25, 1.0 / 3.0}, 1e-4 / 3.0}, {1, 2, {0.0, -0.0, 1e-320}, 0.0}};
  state.wall_history = {{2, 5, {-1.0 / 7.0, 0.0, 2.0}, tiny}};
  return state;
}

template <class T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool sameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

bool sameBits(const Vec3& a, const Vec3& b) {
  return std::memcmp(a.data(), b.data(), sizeof(Vec3)) == 0;
}

void checkSameState(const WorldState& read, const WorldState& written) {
  CHECK(sameBits(read.time, written.time));
  CHECK(read.step == written.step);
  CHECK(sameBits(read.dt, written.dt));
  CHECK(read.half_kick_pending == written.half_kick_pending);
  CHECK(sameBits(read.moving_wall_work, written.moving_wall_work));
  const auto& r = read.particles;
  const auto& w = written.particles;
  CHECK(sameBits(r.position, w.position));
  CHECK(sameBits(r.velocity, w.velocity));
  CHECK(sameBits(r.omega, w.omega));
  CHECK(sameBits(r.radius, w.radius));
  CHECK(sameBits(r.inv_mass, w.inv_mass));
  CHECK(sameBits(r.inv_inertia, w.inv_inertia));
  CHECK(sameBits(r.material, w.material));
  CHECK(sameBits(r.mass, w.mass));
  CHECK(sameBits(r.id, w.id));
  REQUIRE(read.pair_history.size() == written.pair_history.size());
  for (std::size_t k = 0; k < read.pair_history.size(); ++k) {
    CHECK(read.pair_history[k].i == written.pair_history[k].i);
    CHECK(read.pair_history[k].j == written.pair_history[k].j);
    CHECK(sameBits(read.pair_history[k].shear, written.pair_history[k].shear));
    CHECK(sameBits(read.pair_history[k].relax_offset, written.pair_history[k].relax_offset));
  }
  REQUIRE(read.wall_history.size() == written.wall_history.size());
  for (std::size_t k = 0; k < read.wall_history.size(); ++k) {
    CHECK(read.wall_history[k].particle == written.wall_history[k].particle);
    CHECK(read.wall_history[k].wall == written.wall_history[k].wall);
    CHECK(sameBits(read.wall_history[k].shear, written.wall_history[k].shear));
    CHECK(sameBits(read.wall_history[k].relax_offset, written.wall_history[k].relax_offset));
  }
}

/// The message readCheckpoint throws for `path` (fails the test if it does not throw).
std::string readError(const fs::path& path) {
  try {
    output::readCheckpoint(path);
  } catch (const output::CheckpointError& e) {
    return e.what();
  }
  FAIL("readCheckpoint(" << path << ") did not throw CheckpointError");
  return {};
}

/// Lets a test damage a checkpoint file in place.
void editFile(const fs::path& path, const std::function<void(H5::H5File&)>& edit) {
  H5::H5File file(path.string(), H5F_ACC_RDWR);
  edit(file);
}

}  // namespace

TEST_CASE("output: checkpoint round trip keeps every bit", "[output]") {
  TempDir dir;
  const fs::path path = dir / "checkpoint.h5";

  SECTION("particles with contact history") {
    const WorldState state = awkwardState();
    output::writeCheckpoint(path, state, kScene);
    const output::Checkpoint read = output::readCheckpoint(path);
    CHECK(read.scene_text == kScene);
    checkSameState(read.state, state);
  }
  SECTION("an experiment's state: its bytes as they were, and none when none was saved") {
    const std::vector<std::uint8_t> bytes{0xa1, 0x00, 0xff, 0x7f, 0x00};
    output::writeCheckpoint(path, awkwardState(), kScene, bytes);
    CHECK(output::readCheckpoint(path).experiment_state == bytes);
    output::writeCheckpoint(path, awkwardState(), kScene);
    CHECK(output::readCheckpoint(path).experiment_state.empty());
  }
  SECTION("no particles") {
    const WorldState state;  // half_kick_pending = true, empty arrays
    output::writeCheckpoint(path, state, "");
    const output::Checkpoint read = output::readCheckpoint(path);
    CHECK(read.scene_text.empty());
    checkSameState(read.state, state);
  }
  SECTION("a second write replaces the first") {
    output::writeCheckpoint(path, WorldState{}, "first");
    const WorldState state = awkwardState();
    output::writeCheckpoint(path, state, "second");
    const output::Checkpoint read = output::readCheckpoint(path);
    CHECK(read.scene_text == "second");
    checkSameState(read.state, state);
  }
  // Only the checkpoint: the temporary file was renamed into place.
  CHECK(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()) == 1);
}

TEST_CASE("output: checkpoint errors name the file and the problem", "[output]") {
  H5::Exception::dontPrint();
  TempDir dir;
  using Catch::Matchers::Contains;

  SECTION("missing file") {
    const fs::path path = dir / "missing.h5";
    const std::string message = readError(path);
    CHECK_THAT(message, Contains(path.string()) && Contains("does not exist"));
  }
  SECTION("not an HDF5 file") {
    const fs::path path = dir / "scene.toml";
    std::ofstream(path) << "[[spheres]]\n";
    CHECK_THAT(readError(path), Contains(path.string()) && Contains("not an HDF5 file"));
  }
  SECTION("an HDF5 file that is not a checkpoint") {
    const fs::path path = dir / "other.h5";
    H5::H5File(path.string(), H5F_ACC_TRUNC).createGroup("data");
    CHECK_THAT(readError(path), Contains(path.string()) && Contains("not a rocklab checkpoint"));
  }
  SECTION("a run file is not a checkpoint") {
    const fs::path path = dir / "run.h5";
    output::RunFile(path, "").close(false);
    CHECK_THAT(readError(path), Contains(path.string()) && Contains("rocklab-run"));
  }
  SECTION("missing dataset") {
    const fs::path path = dir / "checkpoint.h5";
    output::writeCheckpoint(path, awkwardState(), kScene);
    editFile(path, [](H5::H5File& file) { file.unlink("/particles/mass"); });
    CHECK_THAT(readError(path), Contains(path.string()) && Contains("/particles/mass"));
  }
  SECTION("missing group") {
    const fs::path path = dir / "checkpoint.h5";
    output::writeCheckpoint(path, awkwardState(), kScene);
    editFile(path, [](H5::H5File& file) { file.unlink("/walls"); });
    CHECK_THAT(readError(path), Contains(path.string()) && Contains("missing /walls"));
  }
  SECTION("inconsistent array sizes") {
    const fs::path path = dir / "checkpoint.h5";
    output::writeCheckpoint(path, awkwardState(), kScene);
    editFile(path, [](H5::H5File& file) {
      file.unlink("/particles/radius");
      const hsize_t two = 2;
      file.createDataSet("/particles/radius", H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, &two));
    });
    CHECK_THAT(readError(path), Contains(path.string()) && Contains("radius") &&
                                    Contains("inconsistent array sizes"));
  }
  SECTION("writing an inconsistent state") {
    const fs::path path = dir / "checkpoint.h5";
    WorldState state = awkwardState();
    state.particles.mass.pop_back();
    CHECK_THROWS_WITH(output::writeCheckpoint(path, state, ""),
                      Contains(path.string()) && Contains("mass"));
    CHECK(fs::is_empty(dir.path()));  // neither the checkpoint nor a temporary file
  }
}

TEST_CASE("output: vtk wall series - moving walls at their pose, the spin in the velocity", "[output]") {
  // A gyrating, spinning frustum (the crusher mantle's kind of motion), a static
  // polygon and an infinite plane (not drawn), written at two times and read back.
  rocklab::geometry::FrustumSpec cone;
  cone.bottom_centre = Vec3(0.004, 0, 0);
  cone.top_centre = Vec3(0.001, 0, 0.1);
  cone.bottom_radius = 0.15;
  cone.top_radius = 0.04;
  cone.segments = 24;
  rocklab::sim::Model model;
  rocklab::sim::Wall mantle;
  mantle.name = "mantle";
  mantle.shape = rocklab::sim::WallShape::Mesh;
  mantle.mesh = rocklab::geometry::frustumMesh(cone);
  mantle.motion.angular_velocity = Vec3(0, 0, 31.4);
  mantle.motion.spin_rate = -32.3;
  mantle.motion.spin_axis = (cone.top_centre - cone.bottom_centre).normalized();
  mantle.motion.spin_point = cone.bottom_centre;
  rocklab::sim::Wall gate;
  gate.name = "gate";
  gate.shape = rocklab::sim::WallShape::Polygon;
  gate.vertices = {{-0.2, -0.2, 0.2}, {0.2, -0.2, 0.2}, {0.2, 0.2, 0.2}, {-0.2, 0.2, 0.2}};
  rocklab::sim::Wall floor;
  floor.name = "floor";
  model.walls = {mantle, gate, floor};

  TempDir dir;
  output::VtkSeries series(dir / "vtk", "walls");
  const std::vector<double> times{0.0, 0.05};
  for (const double t : times) series.writeWalls(model, t);
  CHECK(fs::exists(dir / "vtk/walls.pvd"));
  const std::size_t nm = mantle.mesh.vertices.size();
  std::vector<Vec3> first_vertex;
  for (std::size_t f = 0; f < times.size(); ++f) {
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName((dir / ("vtk/walls_00000" + std::to_string(f) + ".vtp")).c_str());
    reader->Update();
    vtkPolyData* poly = reader->GetOutput();
    REQUIRE(poly->GetNumberOfPoints() == static_cast<vtkIdType>(nm + 4));
    REQUIRE(poly->GetNumberOfPolys() == static_cast<vtkIdType>(mantle.mesh.triangleCount() + 2));
    vtkDataArray* wall = poly->GetCellData()->GetArray("wall");
    REQUIRE(wall != nullptr);
    CHECK(wall->GetComponent(0, 0) == 0);
    CHECK(wall->GetComponent(poly->GetNumberOfPolys() - 1, 0) == 1);
    const rocklab::sim::WallPose pose = rocklab::sim::wallPoseAt(mantle.motion, times[f]);
    for (std::size_t k = 0; k < nm; k += 7) {
      const Vec3 x(Eigen::Map<const Vec3>(poly->GetPoint(static_cast<vtkIdType>(k))));
      CHECK((x - pose.place(mantle.mesh.vertices[k])).norm() < 1e-12);
      vtkDataArray* velocity = poly->GetPointData()->GetArray("velocity");
      CHECK((Vec3(Eigen::Map<const Vec3>(velocity->GetTuple3(static_cast<vtkIdType>(k)))) - pose.velocityAt(x)).norm() < 1e-9);
    }
    first_vertex.emplace_back(Eigen::Map<const Vec3>(poly->GetPoint(0)));
    // The static gate stays where it is.
    CHECK(Vec3(Eigen::Map<const Vec3>(poly->GetPoint(static_cast<vtkIdType>(nm)))) == gate.vertices[0]);
  }
  CHECK((first_vertex[1] - first_vertex[0]).norm() > 0.1);  // the mantle moved (1.57 rad about z)
}
