#pragma once
// What sweep, calibrate and study share: a scene run once per variant (a value
// for each varied key, applied like --set), one output folder per run, and the
// results.json figures read back by dotted path. Internal to rocklab_experiments.
#include <filesystem>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/experiments/sweep.h"

namespace rocklab::experiments::detail {

/// One run of a set: its values (one per varied key), what it reported, how it ended.
struct Variant {
  std::vector<std::string> values;
  nlohmann::json results;
  int code = kExitOk;
  std::string status;  // table cell: "ok", "exit 3: <its error>", "missing" ("" = from code)
};

/// Every combination of the varied values, the first key slowest.
std::vector<Variant> expandVariants(const SweepOptions& o);
/// True when a set's source is a checkpoint.h5: each of its runs restarts from it
/// (`rocklab sweep DEPOSIT/checkpoint.h5 --vary ...`), with the scene it was run with.
bool restartsFrom(const std::string& source);
/// The scene of a set's source (file, built-in name, or checkpoint: the scene text
/// it carries) with `overrides`; throws SceneError, a damaged checkpoint included.
Scene loadSetScene(const std::string& source, const std::vector<std::string>& overrides);
/// What a set's messages call its source: a scene file's stem, a checkpoint's run folder.
std::string sourceName(const std::string& source);
/// The absolute path of a set's source, as its run lines name it.
std::filesystem::path sourcePath(const std::string& source);
/// RunOptions of one run of a set into `dir` (the restart from a checkpoint source).
RunOptions setRunOptions(const SweepOptions& o, const std::filesystem::path& dir);
/// Loads the scene with the fixed and the varied assignments (throws SceneError).
Scene sceneFor(const SweepOptions& o, const std::vector<std::string>& values);
/// Runs one variant into dir (its log in dir/run.log); fills v.results and v.code.
void runVariant(const SweepOptions& o, const std::filesystem::path& dir, Variant& v, std::ostream& log);
/// The folder of a set: --out, else out/<scene name><suffix>.
std::filesystem::path outDirFor(const SweepOptions& o, const Scene& scene, const std::string& suffix);
/// "run-007": the folder of the k-th variant.
std::string variantFolder(std::size_t k);

/// results.json value at a dotted path ("wall_time_s.total"); null when absent.
nlohmann::json lookup(const nlohmann::json& r, const std::string& path);
/// A table cell: numbers with 6 digits, booleans as true/false, null as "".
std::string cell(const nlohmann::json& v);
/// A number, a boolean as 0/1, anything else NaN.
double number(const nlohmann::json& v);
/// Parses a whole string as a finite number; throws std::invalid_argument naming `what`.
double toDouble(const std::string& text, const std::string& what);
/// True when every variant ended normally.
bool allOk(const std::vector<Variant>& variants);
/// Writes the table as CSV (atomically) and prints it aligned.
void writeTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                const std::filesystem::path& csv_path, std::ostream& log);

}  // namespace rocklab::experiments::detail
