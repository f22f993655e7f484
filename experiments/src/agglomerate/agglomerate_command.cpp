// `rocklab agglomerate` (see agglomerate_command.h).
#include "agglomerate/agglomerate_command.h"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "agglomerate/agglomerate_library.h"
#include "agglomerate/agglomerate_methods.h"
#include "agglomerate/agglomerate_preview.h"
#include "common/atomic_file.h"
#include "common/json_text.h"
#include "rocklab/experiments/run.h"  // ExitCode
#include "rocklab/geometry/mesh_check.h"

namespace rocklab::experiments {

namespace {

using namespace agglomerate;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string num(double v) {
  std::ostringstream s;
  s << std::setprecision(9) << v;
  return s.str();
}

constexpr int kMostAgglomerates = 10000;

void validate(const AgglomerateOptions& o) {
  auto bad = [](const std::string& option, const std::string& value, const std::string& allowed) {
    throw BadInput(option + " '" + value + "': " + allowed);
  };
  if (o.method != "dense" && o.method != "hcp" && o.method != "mesh")
    bad("--method", o.method, "allowed are dense, hcp, mesh");
  if (o.out.empty()) bad("--out", "", "give the library file to write (LIB.h5)");
  if (o.out.extension() != ".h5")
    bad("--out", o.out.string(), "the library file name must end in .h5");
  if (!(o.r_max > 0 && o.r_max < 1))
    bad("--r-max", num(o.r_max), "allowed is a radius in m in (0, 1)");
  if (o.method != "mesh" && !(o.diameter >= 2 * o.r_max && o.diameter < 10))
    bad("--diameter", num(o.diameter),
        "allowed is a diameter in m, at least 2 r_max (" + num(2 * o.r_max) + ") and < 10");
  if (!(o.r0 >= 1 && o.r0 <= 10))
    bad("--r0", num(o.r0), "allowed is 1..10 (r_max / r_min, Eq 5-11)");
  if (!(o.angle_deg >= 0 && o.angle_deg <= 90))
    bad("--angle", num(o.angle_deg), "allowed is 0..90 degrees");
  if (o.method == "mesh" && o.mesh.empty())
    bad("--mesh", "", "the mesh method needs a mesh file (STL, PLY or OBJ)");
  if (o.method != "mesh" && !o.mesh.empty()) bad("--mesh", o.mesh, "only with --method mesh");
  if (o.method != "mesh" && o.size != 0) bad("--size", num(o.size), "only with --method mesh");
  if (!(o.size >= 0 && o.size < 10))
    bad("--size", num(o.size), "allowed is a size in m in [0, 10) (0 = as in the file)");
  if (o.size_kind != "equivalent" && o.size_kind != "sieve")
    bad("--size-kind", o.size_kind, "allowed are equivalent, sieve");
  if (o.unit != "m" && o.unit != "mm") bad("--unit", o.unit, "allowed are m, mm");
  if (o.count < 1 || o.count > kMostAgglomerates)
    bad("--count", std::to_string(o.count), "allowed is 1.." + std::to_string(kMostAgglomerates));
  if (!(o.gap_tolerance >= 0 && o.gap_tolerance <= 0.1))
    bad("--gap-tolerance", num(o.gap_tolerance), "allowed is 0..0.1 (of the smaller radius)");
  if (o.pack != "servo" && o.pack != "geometric")
    bad("--pack", o.pack, "allowed are servo, geometric");
  if (!(o.pressure >= 1e3 && o.pressure <= 1e8))
    bad("--pressure", num(o.pressure), "allowed is 1e3..1e8 Pa");
}

std::filesystem::path beside(const std::filesystem::path& lib, const char* extension) {
  std::filesystem::path p = lib;
  return p.replace_extension(extension);
}

json packJson(const LoosePack& p) {
  json trials = json::array();
  for (const PackTrial& t : p.trials)
    trials.push_back({{"count", t.count},
                      {"wall_radius_m", t.wall_radius},
                      {"steps", t.steps},
                      {"wall_time_s", t.wall_time_s}});
  return {{"count", p.count},
          {"container_radius_m", p.container_radius},
          {"pressure_Pa", p.pressure},
          {"steps", p.steps},
          {"dt_s", p.dt},
          {"trials", trials},
          {"wall_time_s", p.wall_time_s}};
}

json voidFillJson(const geometry::VoidFillReport& r) {
  return {{"input_spheres", r.input_spheres},
          {"input_dropped", r.input_dropped},
          {"added", r.added},
          {"placed_tangent", r.placed_tangent},
          {"placed_grown", r.placed_grown},
          {"passes", r.passes},
          {"cells_tried", r.cells_tried},
          {"rejected",
           {{"degenerate", r.rejected_degenerate},
            {"no_root", r.rejected_no_root},
            {"centre_outside", r.rejected_centre_outside},
            {"too_small", r.rejected_too_small},
            {"outside_agglomerate", r.rejected_outside_agglomerate},
            {"cannot_fit", r.rejected_cannot_fit}}}};
}

AgglomerateRecord record(const AgglomerateOptions& o, const AgglomerateSpec& spec,
                         const GeneratedAgglomerate& g) {
  AgglomerateRecord r;
  r.method = o.method;
  r.mesh = o.mesh;
  r.r_max = o.r_max;
  r.r0 = spec.method == Method::Hcp ? 1.0 : o.r0;
  r.diameter = g.diameter;
  r.angle_deg = spec.method == Method::Hcp ? o.angle_deg : 0.0;
  r.gap_tolerance = o.gap_tolerance;
  r.mesh_size = o.size;
  r.porosity = g.structure.porosity;
  r.coordination_number = g.structure.coordination_number;
  r.max_overlap = g.structure.max_overlap;
  r.locked_in_stress_Pa = g.locked_in.mean;
  r.seed = spec.seed;
  r.spheres = g.spheres;
  for (const auto& [a, b] : g.bonds)
    r.bonds.push_back({static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b)});
  r.sphere_count = r.spheres.size();
  r.bond_count = r.bonds.size();
  return r;
}

json agglomerateJson(const AgglomerateRecord& r, const GeneratedAgglomerate& g) {
  json j = {{"name", r.name},
            {"seed", r.seed},
            {"porosity", r.porosity},
            {"coordination_number", r.coordination_number},
            {"sphere_count", r.sphere_count},
            {"bond_count", r.bond_count},
            {"max_overlap", r.max_overlap},
            {"max_overlap_fraction", g.structure.max_overlap_fraction},
            {"overlapping_pairs", g.structure.overlapping_pairs},
            {"locked_in_stress_Pa", r.locked_in_stress_Pa},
            {"diameter_m", r.diameter},
            {"envelope_volume_m3", g.structure.envelope_volume},
            {"wall_time_s", g.wall_time_s}};
  if (g.pack) j["pack"] = packJson(*g.pack);
  if (g.void_fill) j["void_fill"] = voidFillJson(*g.void_fill);
  return j;
}

AgglomerateSpec specFor(const AgglomerateOptions& o, const MeshSource* mesh) {
  AgglomerateSpec spec;
  spec.method = parseMethod(o.method);
  spec.diameter = o.diameter;
  spec.r_max = o.r_max;
  spec.r0 = o.r0;
  spec.angle_deg = o.angle_deg;
  spec.gap_tolerance = o.gap_tolerance;
  spec.pack.kind = parsePackKind(o.pack);
  spec.pack.servo.target_pressure = o.pressure;
  spec.mesh = mesh;
  return spec;
}

int runUnguarded(const AgglomerateOptions& o, std::ostream& log) {
  const auto t_start = Clock::now();
  std::optional<MeshSource> mesh;
  try {
    validate(o);
    if (o.method == "mesh")
      mesh =
          prepareMeshSource(o.mesh, o.unit == "mm" ? 1e-3 : 1.0, o.size,
                            o.size_kind == "sieve" ? geometry::MeshSizeMeasure::SieveSize
                                                   : geometry::MeshSizeMeasure::EquivalentDiameter,
                            o.r_max, o.gap_tolerance, static_cast<std::size_t>(o.fill_holes));
    if (mesh)
      for (const std::string& w : mesh->repairs) log << "warning: mesh '" << o.mesh << "': " << w << "\n";
  } catch (const BadInput& e) {
    log << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const geometry::MeshCheckError& e) {
    log << "error: --mesh: " << e.what() << "\n";
    return kExitBadInput;
  }
  AgglomerateSpec spec = specFor(o, mesh ? &*mesh : nullptr);
  std::vector<AgglomerateRecord> records;
  json rows = json::array();
  for (int k = 0; k < o.count; ++k) {
    spec.seed = o.seed + static_cast<std::uint64_t>(k);
    GeneratedAgglomerate g;
    try {
      g = generateAgglomerate(spec);
    } catch (const PackingError& e) {
      log << "error: agglomerate " << k + 1 << " (seed " << spec.seed << "): " << e.what() << "\n";
      return kExitFailed;
    } catch (const std::invalid_argument& e) {  // impossible sizes, a mesh larger than the pack
      log << "error: agglomerate " << k + 1 << " (seed " << spec.seed << "): " << e.what() << "\n";
      return kExitBadInput;
    }
    if (g.pack) spec.pack.first_count = g.pack->count;  // the next seed starts from this count
    records.push_back(record(o, spec, g));
    records.back().name = agglomerateGroupName(records.size() - 1);
    rows.push_back(agglomerateJson(records.back(), g));
    const AgglomerateRecord& r = records.back();
    log << "agglomerate " << k + 1 << "/" << o.count << " (seed " << r.seed
        << "): " << r.sphere_count << " spheres, " << r.bond_count << " bonds, porosity "
        << std::setprecision(4) << r.porosity << ", coordination " << r.coordination_number
        << ", largest overlap " << r.max_overlap << " m, locked-in stress " << r.locked_in_stress_Pa
        << " Pa";
    if (g.pack)
      log << "; pack " << g.pack->count << " spheres in " << g.pack->trials.size() << " trial(s)";
    log << "; " << g.wall_time_s << " s\n";
  }

  writeAgglomerateLibrary(o.out, records);
  const std::filesystem::path png = beside(o.out, ".png"), results = beside(o.out, ".json");
  std::string preview_note = png.filename().string();
  if (o.preview) {
    try {
      writeAgglomeratePreview(png, records.front().spheres);
    } catch (const std::exception& e) {  // no GL: the library still stands
      preview_note = std::string("not written: ") + e.what();
      log << "warning: preview " << preview_note << "\n";
    }
  } else {
    preview_note = "not asked for";
  }

  const PackMaterial material;
  json r = {{"status", "done"},
            {"library", o.out.filename().string()},
            {"preview", preview_note},
            {"method", o.method},
            {"options",
             {{"diameter_m", o.diameter},
              {"r_max_m", o.r_max},
              {"r0", o.r0},
              {"angle_deg", o.angle_deg},
              {"mesh", o.mesh},
              {"size_m", o.size},
              {"size_kind", o.size_kind},
              {"unit", o.unit},
              {"count", o.count},
              {"seed", o.seed},
              {"gap_tolerance", o.gap_tolerance},
              {"pack", o.pack},
              {"pressure_Pa", o.pressure}}},
            {"bond_rule", "every pair with gap <= gap_tolerance x the smaller radius (" +
                              num(o.gap_tolerance) + "), overlapping pairs included"},
            {"locked_in_stress",
             "mean normal stress (trace / 3, compression > 0) of (1/V) sum l F over the initial "
             "overlaps with the Hertz law (dem-models §4.2, §11); V = the envelope"},
            {"compaction_material",
             {{"law", "hertz_mindlin"},
              {"shear_modulus_Pa", material.shear_modulus},
              {"poisson", material.poisson},
              {"density_kg_m3", material.density},
              {"friction", material.friction},
              {"local_damping", material.local_damping},
              {"contact_damping_normal", material.contact_damping}}},
            {"agglomerates", rows},
            {"wall_time_s", since(t_start)}};
  if (mesh) r["dense_diameter_m"] = mesh->dense_diameter;
  detail::writeAtomically(results, detail::jsonText(r));
  log << o.count << " agglomerate(s) → " << o.out.string() << " (" << results.filename().string()
      << ", " << preview_note << "); " << since(t_start) << " s\n";
  return kExitOk;
}

}  // namespace

int runAgglomerate(const AgglomerateOptions& o, std::ostream& log) {
  try {
    return runUnguarded(o, log);
  } catch (const std::exception& e) {  // an output that cannot be written
    log << "error: rocklab agglomerate: " << e.what() << "\n";
    return kExitFailed;
  }
}

}  // namespace rocklab::experiments
