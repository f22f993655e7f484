// plan.json read back and checked (plan_file.h).
#include "sets/plan_file.h"

#include "common/json_text.h"

#include <algorithm>
#include <fstream>

namespace rocklab::experiments::detail {

namespace {

using json = nlohmann::json;

/// Checked reads of one JSON object; messages name the file and the key path.
class Checked {
 public:
  Checked(const json& node, std::string file, std::string path)
      : node_(node), file_(std::move(file)), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw PlanFileError(file_ + ": key '" + keyPath(key) + "': " + what +
                        "; the plan is damaged: plan the set again (--plan) or restore the file");
  }
  bool has(const std::string& key) const { return node_.is_object() && node_.contains(key); }
  const json& at(const std::string& key) const {
    if (!node_.is_object() || !node_.contains(key)) fail(key, "missing");
    return node_[key];
  }
  std::string string(const std::string& key, bool required_non_empty) const {
    const json& v = at(key);
    if (!v.is_string() || (required_non_empty && v.get<std::string>().empty()))
      fail(key, required_non_empty ? "expected a non-empty string" : "expected a string");
    return v.get<std::string>();
  }
  std::vector<std::string> strings(const std::string& key, bool required_non_empty) const {
    const json& v = at(key);
    const bool ok = v.is_array() && std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_string(); });
    if (!ok || (required_non_empty && v.empty()))
      fail(key, required_non_empty ? "expected a non-empty array of strings" : "expected an array of strings");
    return v.get<std::vector<std::string>>();
  }
  std::vector<Checked> objects(const std::string& key) const {
    const json& v = at(key);
    if (!v.is_array() || v.empty()) fail(key, "expected a non-empty array of objects");
    std::vector<Checked> out;
    for (std::size_t k = 0; k < v.size(); ++k) {
      Checked entry(v[k], file_, keyPath(key) + "." + std::to_string(k));
      if (!v[k].is_object()) entry.fail("", "expected an object");
      out.push_back(entry);
    }
    return out;
  }

 private:
  std::string keyPath(const std::string& key) const {
    return path_.empty() ? key : key.empty() ? path_ : path_ + "." + key;
  }
  const json& node_;
  std::string file_, path_;
};

/// A run folder under runs/: one plain name, never a path out of the set.
bool plainName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name.find_first_of("/\\") == std::string::npos;
}

void checkStudy(const Checked& plan, const json& raw, const SweepOptions& o, std::size_t runs) {
  plan.string("figure", true);
  if (raw.contains("seeds")) {
    const json& s = raw["seeds"];
    if (!s.is_number_integer() || s.get<long long>() < 1 || s.get<long long>() > static_cast<long long>(runs))
      plan.fail("seeds", "expected a whole number from 1 to the number of runs");
    if (s.get<long long>() > 1 && o.vary.back().first != "scene.seed")
      plan.fail("seeds", "more than one seed, but the last varied key is not scene.seed");
  }
  if (raw.contains("tolerance_pct") && !(raw["tolerance_pct"].is_number() && raw["tolerance_pct"].get<double>() > 0))
    plan.fail("tolerance_pct", "expected a number > 0");
  if (raw.contains("description") && !raw["description"].is_string()) plan.fail("description", "expected a string");
}

}  // namespace

std::string resultStatus(const json& results) {
  if (!results.is_object()) return "";
  const auto it = results.find("status");
  return it != results.end() && it->is_string() ? it->get<std::string>() : "";
}

bool runCompleted(const std::filesystem::path& dir) {
  return resultStatus(readJsonFile(dir / "results.json")) == "completed";
}

PlanFile readPlanFile(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / "plan.json";
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw PlanFileError(file + " is missing or not a file; give the folder of a sweep or study (made with --plan or --jobs)");
  PlanFile p;
  p.raw = readJsonFile(path);
  if (p.raw.is_discarded() || !p.raw.is_object())
    throw PlanFileError(file + " is not a JSON object; give the folder of a sweep or study (made with --plan or --jobs)");
  const Checked plan(p.raw, file, "");
  p.kind = plan.string("kind", true);
  if (p.kind != "sweep" && p.kind != "study") plan.fail("kind", "expected \"sweep\" or \"study\"");
  p.options.scene = plan.string("scene", true);
  p.options.overrides = plan.strings("overrides", false);
  for (const Checked& v : plan.objects("vary")) p.options.vary.emplace_back(v.string("key", true), v.strings("values", true));
  for (const Checked& r : plan.objects("runs")) {
    PlannedRun run;
    run.name = r.string("name", true);
    if (!plainName(run.name)) r.fail("name", "expected a folder name under runs/, not a path");
    run.values = r.strings("values", false);
    if (run.values.size() != p.options.vary.size())
      r.fail("values", "expected one value per varied key (" + std::to_string(p.options.vary.size()) + ")");
    run.overrides = r.strings("overrides", false);
    run.invalid = r.has("invalid") ? r.string("invalid", false) : "";
    p.runs.push_back(run);
  }
  if (p.kind == "sweep") {
    p.metrics = plan.strings("metrics", true);
    if (plan.has("x_over")) p.options.x_over = plan.string("x_over", true);
  } else {
    checkStudy(plan, p.raw, p.options, p.runs.size());
  }
  return p;
}

}  // namespace rocklab::experiments::detail
