// `rocklab shape` (see shape.h and docs/shape.md).
#include "rocklab/experiments/shape.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <numbers>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "common/preview_renderer.h"
#include "analysis/plot.h"
#include "common/atomic_file.h"
#include "common/json_text.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/geometry/mesh_check.h"
#include "rocklab/geometry/mesh_generate.h"
#include "rocklab/geometry/mesh_properties.h"
#include "rocklab/geometry/mesh_to_clump.h"
#include "rocklab/render/image_io.h"
#include "rocklab/render/renderer.h"

namespace rocklab::experiments {

namespace {

using geometry::Mat3;
using geometry::Sphere;
using geometry::Vec3;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Implausible particle sizes in metres: a file in mm read as m gives a 20 m pebble,
// one in m read as mm a 0.02 mm grain.
constexpr double kSmallestParticle = 1e-4;
constexpr double kSmallestInMillimetres = 1e-3;  // with --unit mm: under 1 mm across, probably metres
constexpr double kLargestParticle = 5.0;
// Surface samples for the surface error (and the surface method's random nodes).
constexpr int kErrorSamples = 20000;

void validate(const ShapeOptions& o) {
  auto bad = [](const std::string& option, const std::string& value, const std::string& allowed) {
    throw BadInput(option + " '" + value + "': " + allowed);
  };
  if (o.mesh.empty()) bad("MESH", "", "give a mesh file (STL, PLY or OBJ)");
  if (o.out_dir.empty()) bad("--out", "", "give an output directory");
  if (o.method != "surface" && o.method != "medial")
    bad("--method", o.method, "allowed are surface, medial");
  if (o.spheres < 1 || o.spheres > 5000)
    bad("--spheres", std::to_string(o.spheres), "allowed is 1..5000");
  if (!(o.tolerance >= 0 && o.tolerance < 1))
    bad("--tolerance", std::to_string(o.tolerance), "allowed is [0, 1)");
  if (o.unit != "m" && o.unit != "mm") bad("--unit", o.unit, "allowed are m, mm");
  if (!(o.size >= 0))
    bad("--size", std::to_string(o.size), "allowed is a length in m > 0 (0 = as in the file)");
  if (o.size_kind != "equivalent" && o.size_kind != "sieve")
    bad("--size-kind", o.size_kind, "allowed are equivalent, sieve");
  if (!(o.density > 0)) bad("--density", std::to_string(o.density), "allowed is > 0 kg/m^3");
  if (!(o.min_radius >= 0 && o.min_radius < 0.5))
    bad("--min-radius", std::to_string(o.min_radius),
        "allowed is [0, 0.5) of the equivalent diameter");
  if (!(o.touch >= 0 && o.touch <= 0.1))
    bad("--touch", std::to_string(o.touch), "allowed is [0, 0.1] of the equivalent diameter");
  if (o.grid < 8 || o.grid > 256) bad("--grid", std::to_string(o.grid), "allowed is 8..256 cells");
  for (int n : o.sweep)
    if (n < 1 || n > 5000) bad("--sweep", std::to_string(n), "sphere counts must be in 1..5000");
  if (o.pile && o.sweep.empty()) bad("--pile", "", "needs --sweep (the counts to time)");
  if (o.pile_clumps < 1 || o.pile_clumps > 5000)
    bad("--pile-clumps", std::to_string(o.pile_clumps), "allowed is 1..5000");
  if (!(o.pile_time > 0 && o.pile_time <= 10))
    bad("--pile-time", std::to_string(o.pile_time), "allowed is (0, 10] s");
}

// The mesh as the clump sees it: checked, in metres, at the target size, in its
// principal frame about its centroid; and how to get back to the file's frame.
struct Prepared {
  geometry::TriangleMesh mesh;  // canonical frame, m
  geometry::MeshCheckReport check;
  geometry::MeshMassProperties props;  // canonical frame, at the density
  geometry::ShapeDescriptors shape;
  double metres_per_file_unit = 1.0;  // unit × size factor
  double size_factor = 1.0;
  Mat3 axes = Mat3::Identity();  // x_file_m = axes x + centroid
  Vec3 centroid = Vec3::Zero();  // m (file frame, scaled)
  double largest_as_read = 0;    // m, in the stated unit, before --size
};

Prepared prepare(const ShapeOptions& o, std::ostream& log) {
  Prepared p;
  const double unit = o.unit == "mm" ? 1e-3 : 1.0;
  geometry::TriangleMesh raw;
  try {
    raw = geometry::checkAndRepairMesh(geometry::readMeshFile(o.mesh, unit), o.mesh, p.check,
                                       static_cast<std::size_t>(o.fill_holes));
  } catch (const geometry::MeshCheckError& e) {
    throw BadInput(e.what());
  }
  for (const std::string& w : p.check.warnings)
    log << "warning: mesh '" << o.mesh << "': " << w << "\n";
  auto props = geometry::meshMassProperties(raw, o.density);
  auto shape = geometry::shapeDescriptors(raw, props);
  p.largest_as_read = shape.long_dim;
  // A scan in metres read with --unit mm is a thousand times too small: below a
  // millimetre across it is far more likely that than a grain of sand.
  const double smallest = o.unit == "mm" ? kSmallestInMillimetres : kSmallestParticle;
  if (p.largest_as_read < smallest || p.largest_as_read > kLargestParticle) {
    std::ostringstream w;
    w << "implausible size for --unit " << o.unit << ": longest dimension " << p.largest_as_read
      << " m (a particle is expected between " << smallest << " and " << kLargestParticle << " m); ";
    if (o.unit == "mm" && p.largest_as_read < smallest) w << "the file is probably in metres: give --unit m";
    else if (o.unit == "m" && p.largest_as_read > kLargestParticle) w << "the file is probably in mm: give --unit mm";
    else w << "check the unit (--unit mm or m)";
    p.check.warnings.push_back(w.str());
    log << "warning: mesh '" << o.mesh << "': " << w.str() << "\n";
  }
  if (o.size > 0) {
    const double current = o.size_kind == "sieve" ? shape.sieve_size : shape.equivalent_diameter;
    p.size_factor = o.size / current;
    raw = geometry::scaled(raw, p.size_factor);
    props = geometry::meshMassProperties(raw, o.density);
  }
  p.metres_per_file_unit = unit * p.size_factor;
  p.axes = props.principal_axes;
  p.centroid = props.centroid;
  p.mesh = geometry::toPrincipalFrame(raw, props);
  p.props = geometry::meshMassProperties(p.mesh, o.density);
  p.shape = geometry::shapeDescriptors(p.mesh, p.props);
  return p;
}

geometry::MeshToClumpOptions clumpOptions(const ShapeOptions& o, const std::string& method,
                                          int spheres) {
  geometry::MeshToClumpOptions c;
  c.method = method == "medial" ? geometry::ClumpMethod::MedialAxis
                                : geometry::ClumpMethod::SurfaceSpheres;
  c.max_spheres = spheres;
  c.volume_tolerance = o.tolerance;
  c.min_radius = o.min_radius;
  c.touch_tolerance = o.touch;
  c.grid_cells = o.grid;
  c.seed = o.seed;
  return c;
}

json vec(const Vec3& v) {
  return json::array({v.x(), v.y(), v.z()});
}
json mat(const Mat3& m) {
  return json::array(
      {vec(m.row(0).transpose()), vec(m.row(1).transpose()), vec(m.row(2).transpose())});
}

json errorJson(const geometry::ClumpFitError& e) {
  return {{"sphere_count", e.spheres},
          {"volume_error", e.volume_error},
          {"inertia_error", e.inertia_error},
          {"inertia_error_mass_scaled", e.inertia_error_mass_scaled},
          {"surface_error_mean_m", e.surface_error_mean},
          {"surface_error_max_m", e.surface_error_max},
          {"union_volume_m3", e.union_volume}};
}

std::string fmt(double v) {
  std::ostringstream s;
  s << std::setprecision(9) << v;
  return s.str();
}

// Clump file (readClumpFile's format) with a header saying where it came from,
// its frame and how its mass is meant to be assigned.
std::string clumpFileText(const ShapeOptions& o, const Prepared& p, const std::string& method,
                          const std::vector<Sphere>& spheres) {
  std::ostringstream s;
  s << "# rocklab shape: " << o.mesh << " (unit " << o.unit << ", scaled x" << fmt(p.size_factor)
    << "), method " << method << ", " << spheres.size() << " spheres\n"
    << "# Frame: centroid and principal axes of the mesh (x = smallest moment = long axis).\n"
    << "# Back to the file's frame: x_file = (R x + t) / s, R rows = " << mat(p.axes).dump()
    << ",\n"
    << "#   t = " << vec(p.centroid).dump() << " m, s = " << fmt(p.metres_per_file_unit)
    << " m per file unit.\n"
    << "# Mass: the spheres only give the contact surface. The solid they stand for is the mesh:\n"
    << "#   mass " << fmt(p.props.mass) << " kg at density " << fmt(o.density) << " kg/m^3 (volume "
    << fmt(p.props.volume) << " m^3),\n"
    << "#   principal moments " << vec(p.props.principal_moments).dump()
    << " kg m^2 (about the centroid).\n"
    << "# Give both in the scene (clump.toml beside this file: mass, principal_inertia); without "
       "them\n"
    << "# the scene takes the union of the spheres (smaller volume and moments).\n"
    << "# x y z r (m)\n";
  for (const Sphere& m : spheres)
    s << fmt(m.centre.x()) << ' ' << fmt(m.centre.y()) << ' ' << fmt(m.centre.z()) << ' '
      << fmt(m.radius) << '\n';
  return s.str();
}

// The [[particles]] keys that give a scene the mesh's mass and inertia.
std::string particlesSnippet(const ShapeOptions& o, const Prepared& p,
                             const std::string& clump_file) {
  std::ostringstream s;
  s << "# Keys for a [[particles]] source using this clump (rocklab shape, density "
    << fmt(o.density) << " kg/m^3):\n"
    << "shape = \"file\"\n"
    << "file = \"" << clump_file << "\"\n"
    << "mass = " << fmt(p.props.mass) << "  # kg, the mesh's exact mass\n"
    << "principal_inertia = [" << fmt(p.props.principal_moments.x()) << ", "
    << fmt(p.props.principal_moments.y()) << ", " << fmt(p.props.principal_moments.z())
    << "]  # kg m^2, the mesh's exact principal moments\n";
  return s.str();
}

// Mesh (left) and clump (right) side by side, seen from the front and a little above.
void writePreview(const std::filesystem::path& png, const geometry::TriangleMesh& mesh,
                  const std::vector<Sphere>& spheres) {
  const geometry::AABB box = mesh.bounds();
  const double L = (box.hi - box.lo).maxCoeff();
  const double shift = detail::sideBySideShift(L);
  render::Renderer renderer = detail::sideBySideRenderer(L);
  render::FrameDescription f;
  f.background = render::kBackdrop;
  render::MeshInstance m;
  m.mesh = std::make_shared<const geometry::TriangleMesh>(mesh);
  m.translation = Vec3(-shift, 0, 0);
  m.colour = render::kGreyPebble;
  f.meshes.push_back(m);
  // Members in alternating tones so that they can be told apart.
  const render::Rgb tones[4] = {
      {0.72f, 0.55f, 0.35f}, {0.55f, 0.62f, 0.70f}, {0.62f, 0.70f, 0.50f}, {0.75f, 0.60f, 0.62f}};
  for (std::size_t k = 0; k < spheres.size(); ++k)
    f.spheres.push_back(
        {spheres[k].centre + Vec3(shift, 0, 0), spheres[k].radius, tones[k % 4], Vec3::Zero()});
  render::writePng(png, renderer.render(f));
}

struct SweepRow {
  std::string method;
  geometry::ClumpFitError error;
  double generate_s = 0;
  double ball_steps_per_s = NAN, clump_steps_per_s = NAN, pile_wall_s = NAN, pile_dt = NAN;
};

// A settling pile of `count` clumps in a box 7.5 d wide, dropped from up to 12 d:
// the simulation cost of this clump shape (particle-steps per second).
std::string pileScene(const ShapeOptions& o, const Prepared& p,
                      const std::filesystem::path& clump_file, int n) {
  const double d = p.shape.equivalent_diameter, w = 7.5 * d;
  std::ostringstream s;
  s << "[scene]\nname = \"shape-pile-" << n << "\"\ndescription = \"" << o.pile_clumps
    << " mesh clumps settling in a box (cost of a clump shape)\"\nseed = 1\nend_time = "
    << fmt(o.pile_time) << "\n\n"
    << "[materials.rock]\ndensity = " << fmt(o.density)
    << "\nkn = 1e7\nks = 1e7\nfriction = 0.37\n\n"
    << "[contact]\nlaw = \"linear\"\ndamping_normal = 0.11\ndamping_shear = 0.11\n\n"
    << "[gravity]\nvector = [0.0, 0.0, -9.81]\n\n"
    << "[[walls]]\ntype = \"box\"\nname = \"box\"\nmaterial = \"rock\"\nmin = [0.0, 0.0, 0.0]\nmax "
       "= ["
    << fmt(w) << ", " << fmt(w) << ", " << fmt(40 * d) << "]\n\n"
    << "[[particles]]\ntype = \"random\"\nmaterial = \"rock\"\n"
    << "shape = \"file\"\nfile = \"" << clump_file.string() << "\"\nmass = " << fmt(p.props.mass)
    << "\nprincipal_inertia = [" << fmt(p.props.principal_moments.x()) << ", "
    << fmt(p.props.principal_moments.y()) << ", " << fmt(p.props.principal_moments.z())
    << "]\ncount = " << o.pile_clumps << "\nregion_min = [0.0, 0.0, 0.0]\nregion_max = [" << fmt(w)
    << ", " << fmt(w) << ", " << fmt(12 * d) << "]\n\n"
    << "[output]\ncheckpoint = false\nhdf5 = false\n";
  return s.str();
}

void runPile(const ShapeOptions& o, const Prepared& p, const std::vector<Sphere>& spheres,
             SweepRow& row, std::ostream& log) {
  const int n = static_cast<int>(spheres.size());
  const std::filesystem::path dir = o.out_dir / ("pile-" + row.method + "-" + std::to_string(n));
  std::filesystem::create_directories(dir);
  const std::filesystem::path clump = std::filesystem::absolute(dir / "clump.txt");
  detail::writeAtomically(clump, clumpFileText(o, p, row.method, spheres));
  const std::string text = pileScene(o, p, clump, n);
  detail::writeAtomically(dir / "pile.toml", text);
  const Scene scene = loadSceneText(text, (dir / "pile.toml").string());
  RunOptions ro;
  ro.out_dir = dir;
  ro.threads = 1;  // one thread, so every count is timed alike
  ro.progress = false;
  const auto t0 = Clock::now();
  std::ostringstream run_log;
  if (runScene(scene, ro, run_log) != kExitOk)
    throw std::runtime_error("pile run failed: " + run_log.str());
  row.pile_wall_s = since(t0);
  const json r = detail::readJsonFile(dir / "results.json");
  row.ball_steps_per_s = r.at("particle_steps_per_s").get<double>();
  row.clump_steps_per_s = row.ball_steps_per_s / n;
  row.pile_dt =
      r.at("dt_s").get<double>();  // the members' size sets the step: cost per simulated second
  log << "pile " << row.method << " " << n << " spheres: " << row.clump_steps_per_s
      << " clump-steps/s (" << row.pile_wall_s << " s)\n";
}

/// --generate: a seeded particle mesh written to o.mesh (about 1 across, then at --size
/// in the stated unit).
void generateMesh(const ShapeOptions& o, std::ostream& log) {
  geometry::ParticleKind kind{};
  try {
    kind = geometry::parseParticleKind(o.generate);
  } catch (const std::invalid_argument& e) {
    throw BadInput(std::string("--generate: ") + e.what());
  }
  geometry::TriangleMesh m = geometry::generateParticle(kind, o.seed);
  if (o.size > 0) {
    const auto props = geometry::meshMassProperties(m);
    const auto shape = geometry::shapeDescriptors(m, props);
    m = geometry::scaled(
        m, o.size / (o.size_kind == "sieve" ? shape.sieve_size : shape.equivalent_diameter) /
               (o.unit == "mm" ? 1e-3 : 1.0));
  }
  try {
    geometry::writeMeshFile(o.mesh, m);
  } catch (const std::exception& e) {
    throw BadInput(e.what());
  }
  log << "generated " << o.generate << " (seed " << o.seed << ") → " << o.mesh << "\n";
}

/// Seconds of each part of the tool, for results.json.
struct ShapeTimes {
  Clock::time_point start;
  double read = 0, generate = 0, errors = 0, preview = 0;
};

/// The clump of the asked method and size, and why the generator stopped.
geometry::ClumpResult makeClump(const ShapeOptions& o, const Prepared& p, ShapeTimes& times) {
  const auto t0 = Clock::now();
  geometry::ClumpResult clump = geometry::meshToClumpWithStop(p.mesh, clumpOptions(o, o.method, o.spheres));
  times.generate = since(t0);
  return clump;
}

/// Whether the clump reached what was asked: with --tolerance the uncovered volume
/// fraction; without, the sphere count (or a fully covered inside, where more
/// spheres add nothing). "" when met, else what was not.
std::string targetMissed(const ShapeOptions& o, const geometry::ClumpResult& clump) {
  std::ostringstream s;
  if (o.tolerance > 0) {
    if (clump.uncovered <= o.tolerance) return "";
    s << "--tolerance " << o.tolerance << " not reached: " << std::setprecision(3) << 100 * clump.uncovered
      << " % of the volume uncovered with " << clump.spheres.size() << " spheres";
  } else {
    if (clump.stop == geometry::ClumpStop::Spheres || clump.stop == geometry::ClumpStop::Covered) return "";
    s << "--spheres " << o.spheres << " not reached: " << clump.spheres.size() << " spheres";
  }
  s << " (" << geometry::clumpStopReason(clump.stop) << ")";
  return s.str();
}

/// Its errors against the mesh.
geometry::ClumpFitError fitError(const Prepared& p, const std::vector<Sphere>& spheres,
                                 const std::vector<geometry::SurfacePoint>& samples,
                                 ShapeTimes& times) {
  const auto t0 = Clock::now();
  geometry::ClumpFitError error = geometry::clumpFitError(p.props, spheres, samples);
  times.errors = since(t0);
  return error;
}

/// --sweep: the error of both methods at every count (the first n spheres of the
/// largest clump), and with --pile the cost of each count of the asked method.
std::vector<SweepRow> sweepRows(const ShapeOptions& o, const Prepared& p,
                                const std::vector<geometry::SurfacePoint>& samples,
                                std::ostream& log) {
  std::vector<SweepRow> rows;
  const int most = *std::max_element(o.sweep.begin(), o.sweep.end());
  for (const std::string method : {"surface", "medial"}) {
    const auto t0 = Clock::now();
    const auto all = geometry::meshToClump(p.mesh, clumpOptions(o, method, most));
    const double gen = since(t0);
    std::vector<int> counts = o.sweep;
    std::sort(counts.begin(), counts.end());
    for (int n : counts) {
      if (n > static_cast<int>(all.size())) {
        log << "note: " << method << " stops at " << all.size()
            << " spheres (no candidate adds volume); count " << n << " skipped\n";
        continue;
      }
      SweepRow row;
      row.method = method;
      const std::vector<Sphere> first(all.begin(), all.begin() + n);
      row.error = geometry::clumpFitError(p.props, first, samples);
      row.generate_s = gen;
      if (o.pile && method == o.method) runPile(o, p, first, row, log);
      rows.push_back(row);
    }
  }
  return rows;
}

void writeSweepCsv(const std::filesystem::path& file, const std::vector<SweepRow>& rows) {
  std::ostringstream csv;
  csv << "method,spheres,volume_error,inertia_error,inertia_error_mass_scaled,surface_error_mean_m,"
         "surface_error_max_m,"
         "generate_s,pile_ball_steps_per_s,pile_clump_steps_per_s,pile_dt_s,pile_wall_s\n";
  for (const SweepRow& r : rows)
    csv << r.method << ',' << r.error.spheres << ',' << fmt(r.error.volume_error) << ','
        << fmt(r.error.inertia_error) << ',' << fmt(r.error.inertia_error_mass_scaled) << ','
        << fmt(r.error.surface_error_mean) << ',' << fmt(r.error.surface_error_max) << ','
        << fmt(r.generate_s) << ',' << fmt(r.ball_steps_per_s) << ',' << fmt(r.clump_steps_per_s)
        << ',' << fmt(r.pile_dt) << ',' << fmt(r.pile_wall_s) << '\n';
  detail::writeAtomically(file, csv.str());
}

/// Volume, inertia and surface errors against the sphere count, per method.
void writeSweepPlot(const ShapeOptions& o, const Prepared& p, const std::vector<SweepRow>& rows) {
  PlotSpec plot;
  plot.title =
      "Clump error against sphere count: " + std::filesystem::path(o.mesh).filename().string();
  plot.x_label = "spheres";
  plot.y_label = "error (%)";
  for (const std::string method : {"surface", "medial"}) {
    PlotSeries vol{"|volume error| " + method, {}, {}}, inert{"inertia error " + method, {}, {}},
        surf{"mean surface distance / d_eq " + method, {}, {}};
    for (const SweepRow& r : rows) {
      if (r.method != method) continue;
      const double n = static_cast<double>(r.error.spheres);
      vol.x.push_back(n);
      vol.y.push_back(100 * std::abs(r.error.volume_error));
      inert.x.push_back(n);
      inert.y.push_back(100 * r.error.inertia_error);
      surf.x.push_back(n);
      surf.y.push_back(100 * r.error.surface_error_mean / p.shape.equivalent_diameter);
    }
    plot.series.push_back(vol);
    plot.series.push_back(inert);
    plot.series.push_back(surf);
  }
  writePlot(plot, o.out_dir / "shape_sweep.png");
}

/// --pile: clump-steps per second against spheres per clump.
void writeCostPlot(const ShapeOptions& o, const std::vector<SweepRow>& rows) {
  PlotSpec cost;
  cost.title = "Simulation cost of a settling pile of " + std::to_string(o.pile_clumps) + " clumps";
  cost.x_label = "spheres per clump";
  cost.y_label = "clump-steps per second";
  PlotSeries s{"method " + o.method, {}, {}};
  for (const SweepRow& r : rows)
    if (std::isfinite(r.clump_steps_per_s)) {
      s.x.push_back(static_cast<double>(r.error.spheres));
      s.y.push_back(r.clump_steps_per_s);
    }
  cost.series.push_back(s);
  writePlot(cost, o.out_dir / "shape_cost.png");
}

/// preview.png when asked for; what results.json says about it.
std::string previewStep(const ShapeOptions& o, const Prepared& p,
                        const std::vector<Sphere>& spheres, ShapeTimes& times, std::ostream& log) {
  if (!o.preview) return "not asked for";
  std::string note = "preview.png";
  const auto t0 = Clock::now();
  try {
    writePreview(o.out_dir / "preview.png", p.mesh, spheres);
  } catch (const std::exception& e) {  // no GL: the numbers still stand
    note = std::string("not written: ") + e.what();
    log << "warning: preview " << note << "\n";
  }
  times.preview = since(t0);
  return note;
}

json meshJson(const ShapeOptions& o, const Prepared& p) {
  return {{"file", o.mesh},
          {"generated", o.generate.empty() ? json(nullptr) : json(o.generate)},
          {"triangles_read", p.check.input_triangles},
          {"triangles", p.mesh.triangles.size()},
          {"vertices", p.mesh.vertices.size()},
          {"volume_m3", p.props.volume},
          {"area_m2", p.props.area},
          {"mass_kg", p.props.mass},
          {"principal_moments_kg_m2", vec(p.props.principal_moments)},
          {"equivalent_diameter_m", p.shape.equivalent_diameter},
          {"sieve_size_m", p.shape.sieve_size},
          {"dimensions_m",
           {{"long", p.shape.long_dim},
            {"intermediate", p.shape.intermediate_dim},
            {"short", p.shape.short_dim}}},
          {"elongation", p.shape.elongation},
          {"flatness", p.shape.flatness},
          {"sphericity", p.shape.sphericity},
          {"longest_dimension_as_read_m", p.largest_as_read},
          {"size_factor", p.size_factor}};
}

json checksJson(const geometry::MeshCheckReport& c) {
  return {{"warnings", c.warnings},
          {"degenerate_removed", c.collapsed_removed},
          {"holes_filled", c.holes_filled},
          {"hole_triangles_added", c.hole_triangles_added},
          {"zero_area_triangles", c.zero_area},
          {"flipped_inconsistent", c.flipped_inconsistent},
          {"flipped_inward", c.flipped_inward},
          {"shells", c.shells},
          {"dropped_triangles", c.dropped_triangles}};
}

json clumpJson(const Prepared& p, const std::vector<Sphere>& spheres) {
  json clump = {{"file", "clump.txt"},
                {"scene_keys", "clump.toml"},
                {"frame", "centroid and principal axes of the mesh"},
                {"to_file_frame",
                 {{"formula", "x_file = (R x + t) / s"},
                  {"R", mat(p.axes)},
                  {"t_m", vec(p.centroid)},
                  {"s_m_per_file_unit", p.metres_per_file_unit}}},
                {"mass_assignment",
                 "the members give the contact surface only; mass and principal_inertia in "
                 "clump.toml are the mesh's "
                 "exact values at the density (scene keys mass, principal_inertia); without them a "
                 "scene uses the "
                 "union of the spheres (volume_error and inertia_error above)"},
                {"members", json::array()}};
  for (const Sphere& s : spheres)
    clump["members"].push_back({s.centre.x(), s.centre.y(), s.centre.z(), s.radius});
  return clump;
}

json sweepJson(const std::vector<SweepRow>& rows) {
  json sweep = json::array();
  for (const SweepRow& row : rows) {
    json j = errorJson(row.error);
    j["method"] = row.method;
    if (std::isfinite(row.clump_steps_per_s)) {
      j["pile_clump_steps_per_s"] = row.clump_steps_per_s;
      j["pile_ball_steps_per_s"] = row.ball_steps_per_s;
      j["pile_wall_s"] = row.pile_wall_s;
      j["pile_dt_s"] = row.pile_dt;
    }
    sweep.push_back(j);
  }
  return sweep;
}

json resultsJson(const ShapeOptions& o, const Prepared& p, const std::vector<Sphere>& spheres,
                 const geometry::ClumpFitError& err, const std::vector<SweepRow>& rows,
                 const ShapeTimes& times, const std::string& preview_note) {
  json r = errorJson(err);
  r["status"] = "done";
  r["wall_time_s"] = times.generate;
  r["timing_s"] = {{"read_and_check", times.read},
                   {"generate", times.generate},
                   {"errors", times.errors},
                   {"preview", times.preview},
                   {"total", since(times.start)}};
  r["method"] = o.method;
  r["options"] = {{"spheres", o.spheres},
                  {"tolerance", o.tolerance},
                  {"min_radius_of_deq", o.min_radius},
                  {"touch_of_deq", o.touch},
                  {"grid", o.grid},
                  {"seed", o.seed},
                  {"unit", o.unit},
                  {"size_m", o.size},
                  {"size_kind", o.size_kind},
                  {"density_kg_m3", o.density}};
  r["mesh"] = meshJson(o, p);
  r["checks"] = checksJson(p.check);
  r["clump"] = clumpJson(p, spheres);
  r["preview"] = preview_note;
  if (!rows.empty()) r["sweep"] = sweepJson(rows);
  return r;
}

int runShapeUnguarded(const ShapeOptions& o, std::ostream& log) {
  ShapeTimes times{Clock::now()};
  Prepared p;
  try {
    validate(o);
    if (!o.generate.empty()) generateMesh(o, log);
    p = prepare(o, log);
  } catch (const BadInput& e) {
    log << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  times.read = since(times.start);

  geometry::ClumpResult clump;
  try {
    clump = makeClump(o, p, times);
  } catch (const std::exception& e) {
    log << "error: mesh '" << o.mesh << "': " << e.what() << "\n";
    return kExitBadInput;
  }
  const std::vector<Sphere>& spheres = clump.spheres;
  const std::string missed = targetMissed(o, clump);
  const auto samples = geometry::sampleSurface(p.mesh, kErrorSamples, o.seed + 1);
  const geometry::ClumpFitError err = fitError(p, spheres, samples, times);
  std::filesystem::create_directories(o.out_dir);
  detail::writeAtomically(o.out_dir / "clump.txt", clumpFileText(o, p, o.method, spheres));
  detail::writeAtomically(o.out_dir / "clump.toml", particlesSnippet(o, p, "clump.txt"));

  std::vector<SweepRow> rows;
  if (!o.sweep.empty()) {
    rows = sweepRows(o, p, samples, log);
    writeSweepCsv(o.out_dir / "shape_sweep.csv", rows);
    writeSweepPlot(o, p, rows);
    if (o.pile) writeCostPlot(o, rows);
  }
  const std::string preview_note = previewStep(o, p, spheres, times, log);
  json r = resultsJson(o, p, spheres, err, rows, times, preview_note);
  r["status"] = missed.empty() ? "done" : "target_not_met";
  r["stop_reason"] = geometry::clumpStopReason(clump.stop);
  r["uncovered_volume_fraction"] = clump.uncovered;
  if (!missed.empty()) r["message"] = missed;
  detail::writeAtomically(o.out_dir / "results.json", detail::jsonText(r));
  log << o.mesh << ": " << spheres.size() << " spheres (" << o.method << "), volume error "
      << std::showpos << 100 * err.volume_error << std::noshowpos << " %, inertia error "
      << 100 * err.inertia_error << " %, surface error mean " << 1e3 * err.surface_error_mean
      << " mm, max " << 1e3 * err.surface_error_max << " mm; stopped: " << geometry::clumpStopReason(clump.stop)
      << "; " << times.generate << " s → " << o.out_dir.string() << "\n";
  if (!missed.empty()) {
    log << "error: " << missed << "; the clump is written, but it is not what was asked\n";
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace

int runShape(const ShapeOptions& o, std::ostream& log) {
  try {
    return runShapeUnguarded(o, log);
  } catch (const std::exception& e) {  // an output that cannot be written, a pile run that failed
    log << "error: rocklab shape " << o.mesh << ": " << e.what() << "\n";
    return kExitBadInput;
  }
}

}  // namespace rocklab::experiments
