#include "sets/run_set.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/csv.h"
#include "common/json_text.h"
#include "rocklab/sim/output/checkpoint.h"

namespace rocklab::experiments::detail {

using json = nlohmann::json;

std::vector<Variant> expandVariants(const SweepOptions& o) {
  std::vector<Variant> variants(1);
  for (const auto& [key, values] : o.vary) {
    std::vector<Variant> next;
    for (const Variant& p : variants)
      for (const std::string& v : values) {
        Variant q = p;
        q.values.push_back(v);
        next.push_back(q);
      }
    variants = next;
  }
  return variants;
}

bool restartsFrom(const std::string& source) { return std::filesystem::path(source).extension() == ".h5"; }

Scene loadSetScene(const std::string& source, const std::vector<std::string>& overrides) {
  if (!restartsFrom(source)) return loadScene(resolveScene(source), overrides);
  try {
    const sim::output::Checkpoint cp = sim::output::readCheckpoint(source);
    Scene scene = loadSceneText(cp.scene_text, source + ":/scene", overrides, std::filesystem::path(source).parent_path());
    scene.source = source;
    return scene;
  } catch (const sim::output::CheckpointError& e) {
    throw SceneError(e.what());
  }
}

std::string sourceName(const std::string& source) {
  const std::filesystem::path p(source);
  return (restartsFrom(source) ? std::filesystem::absolute(p).parent_path().filename() : p.stem()).string();
}

std::filesystem::path sourcePath(const std::string& source) {
  // Normal form: run lines and plan.json name /runs/deposit, not /work/../runs/deposit.
  return std::filesystem::absolute(restartsFrom(source) ? std::filesystem::path(source) : resolveScene(source))
      .lexically_normal();
}

RunOptions setRunOptions(const SweepOptions& o, const std::filesystem::path& dir) {
  RunOptions ro;
  ro.out_dir = dir;
  ro.threads = o.threads;
  ro.progress = o.progress;
  ro.earlier_run = EarlierRun::Replace;  // a run again into its folder: no old output stays
  if (restartsFrom(o.scene)) ro.restart = o.scene;
  return ro;
}

Scene sceneFor(const SweepOptions& o, const std::vector<std::string>& values) {
  std::vector<std::string> overrides = o.overrides;
  for (std::size_t k = 0; k < o.vary.size(); ++k) overrides.push_back(o.vary[k].first + "=" + values[k]);
  return loadSetScene(o.scene, overrides);
}

void runVariant(const SweepOptions& o, const std::filesystem::path& dir, Variant& p, std::ostream& log) {
  Scene scene = sceneFor(o, p.values);
  std::filesystem::create_directories(dir);
  const RunOptions ro = setRunOptions(o, dir);
  std::ofstream run_log(dir / "run.log");
  p.code = runScene(std::move(scene), ro, run_log);
  p.results = readJsonFile(dir / "results.json");
  log << "  ";
  for (std::size_t k = 0; k < o.vary.size(); ++k) log << o.vary[k].first << " = " << p.values[k] << "  ";
  log << "-> " << (p.code == kExitOk ? "done" : "exit " + std::to_string(p.code)) << " (" << dir.string() << ")\n";
}

std::filesystem::path outDirFor(const SweepOptions& o, const Scene& scene, const std::string& suffix) {
  return o.out_dir.empty() ? std::filesystem::path("out") / (scene.run.name + suffix) : o.out_dir;
}

std::string variantFolder(std::size_t k) {
  std::ostringstream name;
  name << "run-" << std::setw(3) << std::setfill('0') << k;
  return name.str();
}

json lookup(const json& r, const std::string& path) {
  const json* node = &r;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = path.find('.', start);
    const std::string key = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (node->is_array()) {  // a numeric part indexes an array: clump_shapes.0.mass_kg
      std::size_t used = 0, index = 0;
      try {
        index = std::stoul(key, &used);
      } catch (const std::exception&) {
        return nullptr;
      }
      if (used != key.size() || index >= node->size()) return nullptr;
      node = &(*node)[index];
    } else {
      if (!node->is_object() || !node->contains(key)) return nullptr;
      node = &(*node)[key];
    }
    if (dot == std::string::npos) return *node;
    start = dot + 1;
  }
}

std::string cell(const json& v) {
  if (v.is_null()) return "";
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_number()) {
    std::ostringstream s;
    s << std::setprecision(6) << v.get<double>();
    return s.str();
  }
  return v.is_string() ? v.get<std::string>() : v.dump();
}

double number(const json& v) {
  if (v.is_number()) return v.get<double>();
  if (v.is_boolean()) return v.get<bool>() ? 1.0 : 0.0;
  return std::numeric_limits<double>::quiet_NaN();
}

double toDouble(const std::string& text, const std::string& what) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used != text.size() || !std::isfinite(v)) throw std::invalid_argument(text);
    return v;
  } catch (const std::exception&) {
    throw std::invalid_argument(what + ": '" + text + "' is not a number");
  }
}

bool allOk(const std::vector<Variant>& variants) {
  return std::all_of(variants.begin(), variants.end(), [](const Variant& v) { return v.code == kExitOk; });
}

void writeTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                const std::filesystem::path& csv_path, std::ostream& log) {
  std::ostringstream csv;
  for (std::size_t c = 0; c < header.size(); ++c) csv << (c ? "," : "") << csvCell(header[c]);
  csv << "\n";
  for (const auto& row : rows) {
    for (std::size_t c = 0; c < row.size(); ++c) csv << (c ? "," : "") << csvCell(row[c]);
    csv << "\n";
  }
  writeAtomically(csv_path, csv.str());
  std::vector<std::size_t> width(header.size());
  for (std::size_t c = 0; c < header.size(); ++c) {
    width[c] = header[c].size();
    for (const auto& row : rows) width[c] = std::max(width[c], row[c].size());
  }
  auto print = [&](const std::vector<std::string>& row) {
    for (std::size_t c = 0; c < row.size(); ++c) log << "  " << std::setw(static_cast<int>(width[c])) << row[c];
    log << "\n";
  };
  print(header);
  for (const auto& row : rows) print(row);
}

}  // namespace rocklab::experiments::detail
