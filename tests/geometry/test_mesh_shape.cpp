// Mesh import checks, exact mesh mass properties and mesh → clump generators.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>

#include "rocklab/geometry/mesh_check.h"
#include "rocklab/geometry/mesh_generate.h"
#include "rocklab/geometry/mesh_properties.h"
#include "rocklab/geometry/mesh_to_clump.h"
#include "rocklab/geometry/mesh_voxels.h"

using namespace rocklab::geometry;
namespace fs = std::filesystem;

namespace {

fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rocklab-mesh-tests-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

double relErr(double a, double b) { return std::abs(a - b) / std::abs(b); }

// Reads and checks a file; returns the message of the MeshCheckError ("" if none).
std::string checkFile(const fs::path& p, MeshCheckReport& report) {
  try {
    checkAndRepairMesh(readMeshFile(p.string(), 1.0), p.string(), report);
  } catch (const MeshCheckError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST_CASE("box mesh mass properties equal the closed forms", "[mesh]") {
  const double a = 0.03, b = 0.02, c = 0.01, rho = 2700;
  TriangleMesh box = boxMesh(Vec3(1.0, 2.0, 3.0), Vec3(1.0 + a, 2.0 + b, 3.0 + c));  // off the origin, like scans
  // Turn it so that the tensor is full and the principal axes must be found.
  const Mat3 rot = (Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized())).toRotationMatrix();
  for (Vec3& v : box.vertices) v = rot * v;
  const MeshMassProperties p = meshMassProperties(box, rho);
  const double m = rho * a * b * c;
  CHECK(relErr(p.volume, a * b * c) < 1e-9);
  CHECK(relErr(p.area, 2 * (a * b + b * c + c * a)) < 1e-9);
  CHECK((p.centroid - rot * Vec3(1 + a / 2, 2 + b / 2, 3 + c / 2)).norm() < 1e-12);
  // Ascending principal moments of a box: m (b²+c²)/12 etc.
  CHECK(relErr(p.principal_moments[0], m * (b * b + c * c) / 12) < 1e-6);
  CHECK(relErr(p.principal_moments[1], m * (a * a + c * c) / 12) < 1e-6);
  CHECK(relErr(p.principal_moments[2], m * (a * a + b * b) / 12) < 1e-6);
  // The long axis (smallest moment) is the box's x axis turned.
  CHECK(std::abs(std::abs(p.principal_axes.col(0).dot(rot * Vec3::UnitX())) - 1) < 1e-9);
  CHECK(p.principal_axes.determinant() > 0.999);
  const ShapeDescriptors d = shapeDescriptors(box, p);
  CHECK(d.long_dim == Approx(a).epsilon(1e-9));
  CHECK(d.short_dim == Approx(c).epsilon(1e-9));
  CHECK(d.flatness == Approx(0.5).epsilon(1e-9));
}

TEST_CASE("ellipsoid mesh mass properties within 0.5 percent of the analytic ellipsoid", "[mesh]") {
  const double a = 0.02, b = 0.015, c = 0.008, rho = 1000;
  const TriangleMesh e = ellipsoidMesh(a, b, c, 5);
  const MeshMassProperties p = meshMassProperties(e, rho);
  const double v = 4.0 / 3.0 * std::numbers::pi * a * b * c, m = rho * v;
  CHECK(relErr(p.volume, v) < 0.005);
  CHECK(relErr(p.principal_moments[0], m * (b * b + c * c) / 5) < 0.005);
  CHECK(relErr(p.principal_moments[1], m * (a * a + c * c) / 5) < 0.005);
  CHECK(relErr(p.principal_moments[2], m * (a * a + b * b) / 5) < 0.005);
  CHECK(p.centroid.norm() < 1e-9);
}

TEST_CASE("inside grid volume converges to the mesh volume", "[mesh]") {
  const TriangleMesh e = ellipsoidMesh(0.02, 0.015, 0.008, 4);
  const double v = meshMassProperties(e).volume;
  const InsideGrid g = voxelizeInside(e, 64);
  CHECK(relErr(static_cast<double>(g.insideCount()) * std::pow(g.h, 3), v) < 0.03);
  const TriangleMesh box = boxMesh(Vec3::Zero(), Vec3(0.02, 0.01, 0.01));
  const InsideGrid gb = voxelizeInside(box, 40);
  CHECK(relErr(static_cast<double>(gb.insideCount()) * std::pow(gb.h, 3), 2e-6) < 0.03);
}

TEST_CASE("a sphere mesh gives a one-sphere clump within 1 percent of its volume", "[mesh]") {
  const TriangleMesh s = icosphere(4, 0.01);
  const MeshMassProperties p = meshMassProperties(s, 2700);
  const auto samples = sampleSurface(s, 2000, 3);
  for (ClumpMethod method : {ClumpMethod::SurfaceSpheres, ClumpMethod::MedialAxis}) {
    MeshToClumpOptions o;
    o.method = method;
    o.max_spheres = 1;
    o.surface_samples = 2000;
    const auto spheres = meshToClump(s, o);
    REQUIRE(spheres.size() == 1);
    const ClumpFitError e = clumpFitError(p, spheres, samples);
    INFO("method " << static_cast<int>(method) << " volume error " << e.volume_error << " radius " << spheres[0].radius
                   << " centre " << spheres[0].centre.transpose());
    CHECK(std::abs(e.volume_error) < 0.01);
    CHECK(e.inertia_error < 0.02);
    CHECK(spheres[0].centre.norm() < 0.001 * 0.01 + 0.02 * 0.01);
    CHECK(e.surface_error_max < 0.002 * 1.0);
  }
}

TEST_CASE("more spheres never give a worse volume error on the sample meshes", "[mesh]") {
  for (ParticleKind kind : {ParticleKind::Pebble, ParticleKind::Crushed, ParticleKind::Flake}) {
    const TriangleMesh m = scaled(generateParticle(kind, 1, 3), 0.01);
    const MeshMassProperties p = meshMassProperties(m, 2700);
    for (ClumpMethod method : {ClumpMethod::SurfaceSpheres, ClumpMethod::MedialAxis}) {
      MeshToClumpOptions o;
      o.method = method;
      o.max_spheres = 24;
      o.grid_cells = 32;
      o.surface_samples = 2000;
      o.max_candidates = 800;
      const auto all = meshToClump(m, o);
      INFO("kind " << static_cast<int>(kind) << " method " << static_cast<int>(method));
      REQUIRE(all.size() >= 8);
      double previous = 1e9;
      for (std::size_t k : {1u, 2u, 4u, 8u, 16u, 24u}) {
        if (k > all.size()) break;
        const std::vector<Sphere> first(all.begin(), all.begin() + static_cast<long>(k));
        const double err = std::abs(clumpFitError(p, first, {}, 128).volume_error);
        INFO("kind " << static_cast<int>(kind) << " method " << static_cast<int>(method) << " spheres " << k);
        CHECK(err <= previous + 0.005);
        previous = err;
      }
      CHECK(previous < 0.5);  // 24 inscribed spheres hold at least half the volume (flakes are the worst)
    }
  }
}

TEST_CASE("mesh files in the three formats give the same mass properties", "[mesh]") {
  const fs::path dir = tempDir("formats");
  const TriangleMesh m = scaled(generateParticle(ParticleKind::Crushed, 2, 3), 0.01);
  const double v = meshMassProperties(m).volume;
  for (const char* ext : {".stl", ".ply", ".obj"}) {
    const fs::path p = dir / (std::string("rock") + ext);
    writeMeshFile(p.string(), m);
    MeshCheckReport report;
    const TriangleMesh back = checkAndRepairMesh(readMeshFile(p.string(), 1.0), p.string(), report);
    INFO(ext);
    CHECK(back.triangles.size() == m.triangles.size());
    CHECK(back.vertices.size() == m.vertices.size());  // welded across STL's per-face corners
    CHECK(report.warnings.empty());
    CHECK(relErr(meshMassProperties(back).volume, v) < 1e-5);  // float precision of the files
  }
  // ASCII STL (written here by hand: facets with their own corner copies and normals).
  {
    std::ofstream stl(dir / "rock-ascii.stl");
    stl << "solid rock\n";
    for (const auto& t : m.triangles) {
      stl << " facet normal 0 0 0\n  outer loop\n";
      for (auto i : t) stl << "   vertex " << m.vertices[i].x() << ' ' << m.vertices[i].y() << ' ' << m.vertices[i].z() << '\n';
      stl << "  endloop\n endfacet\n";
    }
    stl << "endsolid rock\n";
  }
  MeshCheckReport report;
  const TriangleMesh ascii = checkAndRepairMesh(readMeshFile((dir / "rock-ascii.stl").string(), 1.0), "ascii", report);
  CHECK(ascii.vertices.size() == m.vertices.size());
  CHECK(report.warnings.empty());
  CHECK(relErr(meshMassProperties(ascii).volume, v) < 1e-4);
  // Units: the same file read as millimetres is 1000x smaller.
  const TriangleMesh mm = readMeshFile((dir / "rock.stl").string(), 0.001);
  CHECK(relErr(meshMassProperties(mm).volume, 1e-9 * v) < 1e-5);
}

TEST_CASE("every bad mesh class gives its message", "[mesh]") {
  const fs::path dir = tempDir("bad");
  MeshCheckReport r;
  const TriangleMesh cube = boxMesh(Vec3::Zero(), Vec3(0.01, 0.01, 0.01));

  SECTION("missing file") {
    CHECK_THAT(checkFile(dir / "nothere.stl", r), Catch::Contains("does not exist"));
  }
  SECTION("unreadable file") {
    std::ofstream(dir / "garbage.ply") << "ply\nthis is not a mesh\n";
    CHECK_THAT(checkFile(dir / "garbage.ply", r), Catch::Contains("cannot be read"));
  }
  SECTION("no triangles") {
    std::ofstream(dir / "points.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n";
    const std::string msg = checkFile(dir / "points.obj", r);
    CHECK_THAT(msg, Catch::Contains("no triangles") || Catch::Contains("cannot be read"));
    CHECK_THAT(msg, Catch::Contains("points.obj"));
  }
  SECTION("open boundary edges are counted") {
    TriangleMesh open = cube;
    open.triangles.pop_back();
    writeMeshFile((dir / "open.obj").string(), open);
    const std::string msg = checkFile(dir / "open.obj", r);
    CHECK_THAT(msg, Catch::Contains("not closed: 3 open boundary edges"));
    CHECK_THAT(msg, Catch::Contains("open.obj"));
    CHECK_THAT(msg, Catch::Contains("holes or cracks) at ("));  // where the hole is
  }
  SECTION("non-manifold edges") {
    TriangleMesh fin = cube;  // two cubes sharing one edge: that edge has four triangles
    const TriangleMesh other = boxMesh(Vec3(0.01, 0.01, 0.0), Vec3(0.02, 0.02, 0.01));
    for (const auto& t : other.triangles) {
      std::array<std::uint32_t, 3> u{};
      for (int k = 0; k < 3; ++k) {
        u[k] = static_cast<std::uint32_t>(fin.vertices.size());
        fin.vertices.push_back(other.vertices[t[k]]);
      }
      fin.triangles.push_back(u);
    }
    writeMeshFile((dir / "fin.stl").string(), fin);  // welded on reading
    const std::string msg = checkFile(dir / "fin.stl", r);
    CHECK_THAT(msg, Catch::Contains("1 non-manifold edges"));
    // Where: the shared edge's two ends, short numbers.
    CHECK_THAT(msg, Catch::Contains("(0.01, 0.01, 0)") && Catch::Contains("(0.01, 0.01, 0.01)"));
  }
  SECTION("NaN coordinates are called NaN, not a flat surface") {
    TriangleMesh m = cube;
    m.vertices[5].y() = std::nan("");
    try {
      checkAndRepairMesh(m, "nan", r);
      FAIL("a NaN vertex was accepted");
    } catch (const MeshCheckError& e) {
      CHECK_THAT(e.what(), Catch::Contains("vertex 5 has a NaN coordinate"));
    }
    CHECK_THAT(m.validate(), Catch::Contains("vertex 5 has a NaN coordinate"));  // mesh walls
    m.vertices[5].y() = std::numeric_limits<double>::infinity();
    CHECK_THAT(m.validate(), Catch::Contains("vertex 5 has an infinite coordinate"));
  }
  SECTION("inconsistent orientation is fixed and reported") {
    TriangleMesh m = cube;
    std::swap(m.triangles[3][1], m.triangles[3][2]);
    writeMeshFile((dir / "flip.ply").string(), m);
    CHECK(checkFile(dir / "flip.ply", r).empty());
    CHECK(r.flipped_inconsistent == 1);
    REQUIRE(r.warnings.size() == 1);
    CHECK_THAT(r.warnings[0], Catch::Contains("1 triangles were oriented against their neighbours"));
  }
  SECTION("inward normals are flipped and reported") {
    TriangleMesh m = cube;
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
    writeMeshFile((dir / "inward.obj").string(), m);
    const TriangleMesh fixed = checkAndRepairMesh(readMeshFile((dir / "inward.obj").string(), 1.0), "inward.obj", r);
    CHECK(r.flipped_inward);
    CHECK_THAT(r.warnings.back(), Catch::Contains("inward"));
    CHECK(meshMassProperties(fixed).volume == Approx(1e-6).epsilon(1e-6));
  }
  SECTION("degenerate triangles are reported") {
    // Edge (0,1) of the cube split at its midpoint m; the zero-area triangle (0, 1, m) keeps it closed.
    TriangleMesh m = cube;
    const auto mid = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.push_back(0.5 * (m.vertices[0] + m.vertices[1]));
    // Triangle {0, 2, 1} uses edge 1→0; replace it by {0, 2, m} and {m, 2, 1}; then (0, m, 1) closes it.
    m.triangles[0] = {0, 2, mid};
    m.triangles.push_back({mid, 2, 1});
    m.triangles.push_back({0, mid, 1});
    MeshCheckReport r2;
    const TriangleMesh fixed = checkAndRepairMesh(m, "degenerate", r2);
    CHECK(r2.zero_area == 1);
    CHECK(r2.boundary_edges == 0);
    CHECK_THAT(r2.warnings.at(0), Catch::Contains("zero area"));
    m.triangles.push_back({3, 3, 5});  // collapsed: a repeated corner
    MeshCheckReport r3;
    checkAndRepairMesh(m, "collapsed", r3);
    CHECK(r3.collapsed_removed == 1);
    CHECK_THAT(r3.warnings.at(0), Catch::Contains("1 degenerate triangles (two corners at the same point) removed"));
  }
  SECTION("several shells: the largest is kept") {
    TriangleMesh two = boxMesh(Vec3::Zero(), Vec3(0.01, 0.01, 0.01));
    const TriangleMesh small = boxMesh(Vec3(0.05, 0, 0), Vec3(0.052, 0.002, 0.002));
    const auto base = static_cast<std::uint32_t>(two.vertices.size());
    for (const Vec3& v : small.vertices) two.vertices.push_back(v);
    for (const auto& t : small.triangles) two.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    writeMeshFile((dir / "two.stl").string(), two);
    const TriangleMesh kept = checkAndRepairMesh(readMeshFile((dir / "two.stl").string(), 1.0), "two", r);
    CHECK(r.shells == 2);
    CHECK(kept.triangles.size() == 12);
    CHECK_THAT(r.warnings.at(0), Catch::Contains("2 disconnected shells"));
    CHECK(meshMassProperties(kept).volume == Approx(1e-6).epsilon(1e-6));
  }
}

TEST_CASE("a volume tolerance stops the greedy selection when it is met", "[mesh]") {
  const TriangleMesh m = scaled(generateParticle(ParticleKind::Pebble, 5, 3), 0.01);
  const MeshMassProperties p = meshMassProperties(m, 2700);
  for (double tol : {0.3, 0.1}) {
    MeshToClumpOptions o;
    o.max_spheres = 500;
    o.volume_tolerance = tol;
    o.grid_cells = 32;
    o.surface_samples = 2000;
    o.max_candidates = 800;
    const auto spheres = meshToClump(m, o);
    INFO("tolerance " << tol << ": " << spheres.size() << " spheres");
    CHECK(spheres.size() < 500);
    // The grid's coverage is the stopping measure; the exact union may differ by the cells at the rim.
    const double err = clumpFitError(p, spheres, {}, 128).volume_error;
    CHECK(err < 0.0);
    CHECK(-err < tol + 0.05);
    // One sphere fewer would not have met it (the greedy stops at the first count that does).
    if (spheres.size() > 1) {
      const std::vector<Sphere> fewer(spheres.begin(), spheres.end() - 1);
      CHECK(-clumpFitError(p, fewer, {}, 128).volume_error > tol - 0.05);
    }
  }
}

TEST_CASE("small holes of a scan are closed when asked: the patch restores the volume and faces out", "[mesh]") {
  const TriangleMesh sphere = icosphere(3, 0.02);  // 1280 triangles, closed
  const double volume = meshMassProperties(sphere).volume;
  MeshCheckReport report;

  SECTION("one missing triangle: refused as it is, closed by the same triangle with --fill-holes 3") {
    TriangleMesh open = sphere;
    open.triangles.erase(open.triangles.begin() + 100);
    CHECK_THROWS_WITH(checkAndRepairMesh(open, "scan", report),
                      Catch::Contains("3 open boundary edges") && Catch::Contains("--fill-holes N"));
    const TriangleMesh closed = checkAndRepairMesh(open, "scan", report, 3);
    CHECK(report.holes_filled == 1);
    CHECK(report.hole_triangles_added == 1);
    CHECK(report.flipped_inconsistent == 0);  // the patch runs the way the surface does
    CHECK_FALSE(report.flipped_inward);
    CHECK(closed.triangles.size() == sphere.triangles.size());
    CHECK(meshMassProperties(closed).volume == Approx(volume).epsilon(1e-12));
  }
  SECTION("the fan around a vertex gone (a six-edge hole): closed flat, only with a limit of six or more") {
    TriangleMesh open = sphere;
    const std::uint32_t apex = open.triangles[0][0];
    std::erase_if(open.triangles, [apex](const auto& t) { return t[0] == apex || t[1] == apex || t[2] == apex; });
    const std::size_t removed = sphere.triangles.size() - open.triangles.size();
    REQUIRE((removed == 5 || removed == 6));  // icosahedron corners have five neighbours, the rest six
    CHECK_THROWS_WITH(checkAndRepairMesh(open, "scan", report, removed - 1),
                      Catch::Contains("closed what it could"));
    const TriangleMesh closed = checkAndRepairMesh(open, "scan", report, removed);
    CHECK(report.holes_filled == 1);
    CHECK(report.hole_triangles_added == removed - 2);  // a polygon of n corners: n - 2 triangles
    CHECK(report.flipped_inconsistent == 0);
    CHECK_FALSE(report.flipped_inward);
    // The flat patch cuts off the cap the fan made: a little less volume, never more.
    const double patched = meshMassProperties(closed).volume;
    CHECK(patched < volume);
    CHECK(patched > 0.999 * volume);
  }
}
