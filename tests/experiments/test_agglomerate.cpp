// `rocklab agglomerate` and its parts: the servo wall, the agglomerate methods, the
// library file (round trip and damaged files), the locked-in stress, the CLI.
#include <H5Cpp.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "agglomerate/agglomerate_library.h"
#include "agglomerate/agglomerate_methods.h"
#include "agglomerate/locked_in_stress.h"
#include "agglomerate/servo_pack.h"
#include "cli_support.h"
#include "rocklab/geometry/mesh_generate.h"
#include "rocklab/sim/timestep.h"

namespace fs = std::filesystem;
using namespace rocklab;
using namespace rocklab::experiments::agglomerate;
using experiments::AgglomerateLibraryError;
using experiments::AgglomerateRecord;
using geometry::Sphere;
using geometry::Vec3;

namespace {

fs::path tempDir(const std::string& name) {
  // The process id: other worktrees may run these tests at the same time.
  const fs::path d = fs::temp_directory_path() /
                     ("rocklab-agglomerate-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

bool sameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// A record with awkward doubles (not representable in a short decimal).
AgglomerateRecord sampleRecord(std::uint64_t seed, std::size_t n) {
  AgglomerateRecord r;
  r.method = "dense";
  r.r_max = 0.0025;
  r.r0 = 1.0 / 3.0;
  r.diameter = std::numbers::pi / 60;
  r.gap_tolerance = 1e-3;
  r.porosity = std::sqrt(2.0) / 5;
  r.coordination_number = 4.0 + 1.0 / 7.0;
  r.max_overlap = 1.234567890123e-7;
  r.locked_in_stress_Pa = 98765.4321;
  r.seed = seed;
  geometry::Rng rng(seed);
  for (std::size_t i = 0; i < n; ++i)
    r.spheres.push_back(
        {Vec3(rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02)),
         rng.uniform(6e-4, 2.5e-3)});
  for (std::uint32_t i = 0; i + 1 < n; ++i) r.bonds.push_back({i, i + 1});
  r.sphere_count = r.spheres.size();
  r.bond_count = r.bonds.size();
  return r;
}

std::string libraryError(const fs::path& path) {
  try {
    experiments::readAgglomerateLibrary(path);
  } catch (const AgglomerateLibraryError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("agglomerate library: written and read back bit for bit", "[agglomerate]") {
  const fs::path dir = tempDir("roundtrip");
  std::vector<AgglomerateRecord> lib = {sampleRecord(1, 40), sampleRecord(2, 7),
                                        sampleRecord(3, 1)};
  lib[1].method = "mesh";
  lib[1].mesh = "rock ü.stl";
  lib[1].mesh_size = 0.05;
  lib[2].method = "hcp";
  lib[2].angle_deg = 30;
  experiments::writeAgglomerateLibrary(dir / "lib.h5", lib);
  CHECK_FALSE(fs::exists(dir / "lib.h5.tmp"));
  const auto back = experiments::readAgglomerateLibrary(dir / "lib.h5");
  REQUIRE(back.size() == lib.size());
  for (std::size_t k = 0; k < lib.size(); ++k) {
    const AgglomerateRecord &a = lib[k], &b = back[k];
    CHECK(b.name == experiments::agglomerateGroupName(k));
    CHECK(b.method == a.method);
    CHECK(b.mesh == a.mesh);
    for (auto m : {&AgglomerateRecord::r_max, &AgglomerateRecord::r0, &AgglomerateRecord::diameter,
                   &AgglomerateRecord::angle_deg, &AgglomerateRecord::gap_tolerance,
                   &AgglomerateRecord::mesh_size, &AgglomerateRecord::porosity,
                   &AgglomerateRecord::coordination_number, &AgglomerateRecord::max_overlap,
                   &AgglomerateRecord::locked_in_stress_Pa})
      CHECK(sameBits(a.*m, b.*m));
    CHECK(b.seed == a.seed);
    CHECK(b.sphere_count == a.sphere_count);
    CHECK(b.bond_count == a.bond_count);
    REQUIRE(b.spheres.size() == a.spheres.size());
    for (std::size_t i = 0; i < a.spheres.size(); ++i) {
      CHECK(sameBits(a.spheres[i].radius, b.spheres[i].radius));
      for (int c = 0; c < 3; ++c) CHECK(sameBits(a.spheres[i].centre[c], b.spheres[i].centre[c]));
    }
    CHECK(b.bonds == a.bonds);
  }
}

TEST_CASE("agglomerate library: damaged and foreign files give clear errors", "[agglomerate]") {
  const fs::path dir = tempDir("bad");
  CHECK_THAT(libraryError(dir / "missing.h5"), Catch::Contains("does not exist"));
  std::ofstream(dir / "text.h5") << "not hdf5\n";
  CHECK_THAT(libraryError(dir / "text.h5"), Catch::Contains("not an HDF5 file"));
  { H5::H5File f((dir / "empty.h5").string(), H5F_ACC_TRUNC); }
  CHECK_THAT(libraryError(dir / "empty.h5"), Catch::Contains("not an agglomerate library"));

  // A good library, then damaged one way per copy.
  experiments::writeAgglomerateLibrary(dir / "good.h5", {sampleRecord(1, 10), sampleRecord(2, 10)});
  auto damaged = [&](const std::string& name, const std::function<void(H5::H5File&)>& damage) {
    const fs::path p = dir / (name + ".h5");
    fs::copy_file(dir / "good.h5", p, fs::copy_options::overwrite_existing);
    {
      H5::H5File f(p.string(), H5F_ACC_RDWR);
      damage(f);
    }
    return libraryError(p);
  };
  const std::string bond = damaged("bond", [](H5::H5File& f) {
    const std::uint32_t rows[2] = {3, 57};
    H5::DataSet d = f.openGroup("agglomerate_0001").openDataSet("bonds");
    H5::DataSpace file_space = d.getSpace();
    const hsize_t start[2] = {4, 0}, count[2] = {1, 2};
    file_space.selectHyperslab(H5S_SELECT_SET, count, start);
    d.write(rows, H5::PredType::NATIVE_UINT32, H5::DataSpace(2, count), file_space);
  });
  CHECK_THAT(bond, Catch::Contains("agglomerate_0001") && Catch::Contains("'bonds'") &&
                       Catch::Contains("row 4") && Catch::Contains("beyond the 10 spheres"));
  const std::string radius = damaged("radius", [](H5::H5File& f) {
    std::vector<double> r(10, 1e-3);
    r[6] = -1e-3;
    f.openGroup("agglomerate_0000")
        .openDataSet("radii")
        .write(r.data(), H5::PredType::NATIVE_DOUBLE);
  });
  CHECK_THAT(radius, Catch::Contains("agglomerate_0000") && Catch::Contains("'radii'") &&
                         Catch::Contains("sphere 6"));
  const std::string shape = damaged("shape", [](H5::H5File& f) {
    H5::Group g = f.openGroup("agglomerate_0000");
    g.unlink("centres");
    const hsize_t dims[2] = {10, 2};
    g.createDataSet("centres", H5::PredType::NATIVE_DOUBLE, H5::DataSpace(2, dims));
  });
  CHECK_THAT(shape, Catch::Contains("'centres'") && Catch::Contains("wrong shape") &&
                        Catch::Contains("[n,3]"));
  const std::string missing = damaged("group", [](H5::H5File& f) { f.unlink("agglomerate_0001"); });
  CHECK_THAT(missing, Catch::Contains("agglomerate_0001") && Catch::Contains("missing"));
  const std::string attr = damaged(
      "attr", [](H5::H5File& f) { f.openGroup("agglomerate_0000").removeAttr("porosity"); });
  CHECK_THAT(
      attr, Catch::Contains("agglomerate_0000") && Catch::Contains("missing attribute 'porosity'"));
  const std::string format = damaged("format", [](H5::H5File& f) {
    f.removeAttr("format");
    const H5::StrType t(H5::PredType::C_S1, H5T_VARIABLE);
    f.createAttribute("format", t, H5::DataSpace(H5S_SCALAR))
        .write(t, std::string("rocklab-checkpoint"));
  });
  CHECK_THAT(format, Catch::Contains("format is 'rocklab-checkpoint'"));

  // The writer refuses records that would not read back.
  AgglomerateRecord r = sampleRecord(1, 5);
  r.bonds.push_back({2, 9});
  r.bond_count = r.bonds.size();
  CHECK_THROWS_AS(experiments::writeAgglomerateLibrary(dir / "refused.h5", {r}),
                  AgglomerateLibraryError);
}

TEST_CASE("locked-in stress of two overlapping spheres is the Hertz force on the branch",
          "[agglomerate]") {
  const double r = 2e-3, overlap = 1e-6, G = 70e9, nu = 0.2, V = 1e-6;
  const std::vector<Sphere> s = {{Vec3::Zero(), r}, {Vec3(2 * r - overlap, 0, 0), r}};
  const LockedInStress st = lockedInStress(s, {{0, 1}}, G, nu, V);
  const double F = sim::hertzCoefficient(G, nu, r) * std::pow(overlap, 1.5);  // Eq 2-22, R~ = r
  CHECK(st.tensor(0, 0) == Approx((2 * r - overlap) * F / V));
  CHECK(st.tensor(1, 1) == 0.0);
  CHECK(st.mean == Approx((2 * r - overlap) * F / (3 * V)));
}

TEST_CASE("servo wall compacts a small pack to its target pressure within 1 %", "[agglomerate]") {
  ServoPackParams p;
  p.count = 40;
  p.radius = 2.5e-3;
  p.seed = 3;
  const ServoPackResult r = servoCompactedPack(p);
  INFO("steps " << r.steps << ", wall radius " << r.wall_radius << " m, " << r.wall_time_s << " s");
  CHECK(std::abs(r.pressure - 1e5) < 0.01 * 1e5);
  CHECK(r.kinetic_energy < p.kinetic_fraction * r.elastic_energy);
  CHECK(r.wall_radius < r.initial_wall_radius);
  CHECK(r.wall_contacts > 0);
  // At rest, the balls are inside the wall but for a Hertz penetration well below a radius.
  CHECK(r.max_wall_penetration < 2e-3 * p.radius);
  for (const Sphere& s : r.spheres)
    CHECK(s.centre.norm() + s.radius <= r.wall_radius + 2e-3 * p.radius);
  CHECK(r.first_phase_steps > 0);
  CHECK(r.first_phase_steps < r.steps);
  // The pack is a jammed random pack: solid fraction of the wall's sphere between loose and dense.
  const double solid = 40 * std::pow(p.radius / r.wall_radius, 3);
  CHECK(solid > 0.45);
  CHECK(solid < 0.66);
}

TEST_CASE("small dense agglomerate: porosity, coordination and bonds in range", "[agglomerate]") {
  AgglomerateSpec spec;
  spec.method = Method::Dense;
  spec.diameter = 0.02;
  spec.r0 = 2;
  spec.seed = 1;
  const GeneratedAgglomerate g = generateAgglomerate(spec);
  INFO("spheres " << g.structure.sphere_count << ", porosity " << g.structure.porosity << ", CN "
                  << g.structure.coordination_number);
  CHECK(g.structure.porosity > 0.2);
  CHECK(g.structure.porosity < 0.55);  // 20 mm: the loose shell at the surface weighs
  CHECK(g.structure.coordination_number > 3);
  CHECK(g.structure.coordination_number < 9);
  CHECK(g.void_fill->added > 0);
  REQUIRE(g.pack);
  CHECK(g.pack->container_radius <= 0.01 + 1e-9);
  for (const auto& [a, b] : g.bonds)
    CHECK(geometry::sphereGap(g.spheres[a], g.spheres[b]) <=
          spec.gap_tolerance * std::min(g.spheres[a].radius, g.spheres[b].radius));
  CHECK(g.bonds.size() == g.structure.contact_count);
  // Centred on the centre of mass; every sphere within the diameter.
  Vec3 com = Vec3::Zero();
  double w = 0;
  for (const Sphere& s : g.spheres) {
    com += std::pow(s.radius, 3) * s.centre;
    w += std::pow(s.radius, 3);
  }
  CHECK((com / w).norm() < 1e-12);
  // Overlaps from the 100 kPa pack: small, and a locked-in stress of the order of the pressure.
  CHECK(g.structure.max_overlap_fraction < 1e-3);
  CHECK(g.locked_in.mean > 1e4);
  CHECK(g.locked_in.mean < 1e6);
}

TEST_CASE("HCP agglomerate: coordination 12 in the interior, no locked-in stress",
          "[agglomerate]") {
  AgglomerateSpec spec;
  spec.method = Method::Hcp;
  spec.diameter = 0.042;
  spec.angle_deg = 30;
  const GeneratedAgglomerate g = generateAgglomerate(spec);
  std::vector<int> contacts(g.spheres.size(), 0);
  for (const auto& [a, b] : g.bonds) ++contacts[a], ++contacts[b];
  int interior = 0;
  for (std::size_t i = 0; i < g.spheres.size(); ++i)
    if (g.spheres[i].centre.norm() < 0.021 - 3 * spec.r_max) {
      ++interior;
      CHECK(contacts[i] == 12);
    }
  CHECK(interior > 20);
  CHECK(g.locked_in.mean == Approx(0).margin(1e-6));
}

TEST_CASE("rocklab agglomerate writes a library, its results and a preview", "[agglomerate]") {
  using experiments::test::cli;
  const fs::path dir = tempDir("cli");
  REQUIRE(cli({"agglomerate", "--method", "hcp", "--diameter", "0.02", "--count", "2", "--out",
               (dir / "hcp.h5").string()}) == 0);
  for (const char* f : {"hcp.h5", "hcp.json", "hcp.png"}) CHECK(fs::exists(dir / f));
  const auto lib = experiments::readAgglomerateLibrary(dir / "hcp.h5");
  REQUIRE(lib.size() == 2);
  std::ifstream in(dir / "hcp.json");
  const nlohmann::json r = nlohmann::json::parse(in);
  REQUIRE(r["agglomerates"].size() == 2);
  CHECK(r["agglomerates"][1]["seed"] == 2);
  CHECK(r["agglomerates"][0]["sphere_count"] == lib[0].sphere_count);
  CHECK(r["agglomerates"][0]["bond_count"] == lib[0].bond_count);
  for (const char* key :
       {"porosity", "coordination_number", "max_overlap", "locked_in_stress_Pa", "wall_time_s"})
    CHECK(r["agglomerates"][0].contains(key));
  CHECK(r["options"]["gap_tolerance"] == 1e-3);

  // The mesh method: a generated pebble, carved from a dense agglomerate.
  geometry::writeMeshFile((dir / "pebble.stl").string(),
                          geometry::generateParticle(geometry::ParticleKind::Pebble, 2));
  REQUIRE(cli({"agglomerate", "--method", "mesh", "--mesh", (dir / "pebble.stl").string(), "--size",
               "0.015", "--r0", "2", "--no-preview", "--out", (dir / "pebble.h5").string()}) == 0);
  const auto carved = experiments::readAgglomerateLibrary(dir / "pebble.h5");
  REQUIRE(carved.size() == 1);
  CHECK(carved[0].method == "mesh");
  CHECK(carved[0].sphere_count > 10);
  CHECK_FALSE(fs::exists(dir / "pebble.png"));

  // The geometric stand-in for the DEM pack.
  REQUIRE(cli({"agglomerate", "--diameter", "0.02", "--r0", "2", "--pack", "geometric",
               "--no-preview", "--out", (dir / "geometric.h5").string()}) == 0);
  CHECK(experiments::readAgglomerateLibrary(dir / "geometric.h5")[0].sphere_count > 20);
}

TEST_CASE("rocklab agglomerate refuses bad options with exit code 2", "[agglomerate]") {
  using experiments::test::cli;
  const fs::path dir = tempDir("refuse");
  const std::string out = (dir / "lib.h5").string();
  CHECK(cli({"agglomerate", "--method", "cubic", "--out", out}) == 2);
  CHECK(cli({"agglomerate", "--r0", "0.5", "--out", out}) == 2);
  CHECK(cli({"agglomerate", "--diameter", "0.001", "--out", out}) == 2);
  CHECK(cli({"agglomerate", "--count", "0", "--out", out}) == 2);
  CHECK(cli({"agglomerate", "--angle", "120", "--method", "hcp", "--out", out}) == 2);
  CHECK(cli({"agglomerate", "--pack", "magic", "--out", out}) == 2);
  CHECK(cli({"agglomerate", "--size", "0.05", "--out", out}) == 2);  // --size is the mesh method's
  CHECK(cli({"agglomerate", "--gap-tolerance", "-1", "--out", out}) == 2);
  CHECK(cli({"agglomerate", "--out", (dir / "lib.txt").string()}) == 2);
  CHECK(cli({"agglomerate", "--method", "mesh", "--out", out}) == 2);
  CHECK(cli({"agglomerate", "--method", "mesh", "--mesh", (dir / "none.stl").string(), "--out",
             out}) == 2);
  CHECK(cli({"agglomerate", "--r-max", "abc", "--out", out}) == 2);
  CHECK(cli({"agglomerate", "--method", "hcp"}) == 2);  // no --out
  CHECK_FALSE(fs::exists(out));
}
