#include "rocklab/experiments/scene.h"

#include <fstream>
#include <map>
#include <sstream>

#include "drivers/experiment_settings.h"
#include "scene/scene_internal.h"

#ifndef ROCKLAB_ASSET_DIR
#define ROCKLAB_ASSET_DIR "assets"
#endif

namespace rocklab::experiments {

using detail::TableReader;

namespace {

Scene readScene(const toml::table& root_table, const std::filesystem::path& base_dir,
                std::shared_ptr<const TableReader::Overrides> overrides) {
  Scene scene;
  TableReader root(root_table, "", std::move(overrides));
  // The order is the order of the messages: a scene with two errors reports the
  // first.
  detail::readRunTable(root, scene.run);
  const std::map<std::string, int> materials = detail::readMaterials(root, scene);
  detail::readContact(root, scene.model);
  detail::readGravity(root, scene.model);
  detail::readEngine(root, scene.model);
  detail::readWalls(root, materials, base_dir, scene.model, scene.wall_looks);
  detail::readCrusher(root, materials, scene);
  detail::readParticles(root, materials, scene.model.materials, scene.run.seed, base_dir, scene);
  detail::readBonds(root, scene.run.seed, scene);
  detail::readCameras(root, scene.cameras);
  detail::readExperiment(root, scene);
  detail::readOutput(root, scene.run);
  if (scene.experiment && !scene.experiment->needs_checkpoint.empty() && !scene.run.checkpoint)
    root.table("experiment")
        ->fail(scene.experiment->needs_checkpoint,
               "needs output.checkpoint = true (the run ends there so that its checkpoint.h5 is restarted from)");
  root.finish();
  return scene;
}

toml::table parseToml(const std::string& text, const std::string& source_name) {
  try {
    return toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    std::ostringstream s;
    s << source_name << ":" << e.source().begin.line << ": TOML syntax error: " << e.description();
    throw SceneError(s.str());
  }
}

/// Lays `over` onto `base`: tables merge key by key, anything else (numbers,
/// strings, arrays, arrays of tables such as [[walls]]) replaces the base
/// value.
void mergeInto(toml::table& base, const toml::table& over) {
  for (const auto& [key, value] : over) {
    toml::table* base_table = base[key].as_table();
    if (base_table && value.is_table())
      mergeInto(*base_table, *value.as_table());
    else
      base.insert_or_assign(key, value);
  }
}

/// `remove = ["walls.zone_wall_1", ...]`: drops each named entry of an array of
/// tables after `extends` has merged, so that an extending scene can leave out
/// an inherited wall (or particle set, camera, ...) without repeating the whole
/// array (an array of tables replaces the base's whole). Each entry is
/// ARRAY.NAME, the entry found by its `name` as `--set` finds it
/// (detail::namedEntryIndex); one that names nothing is refused, listing the
/// names the array has.
struct Removals {
  std::string at;  // "file:line: key 'remove'", read before the merge (a merged copy has no source)
  std::vector<std::string> entries;
};

Removals takeRemovals(toml::table& table) {
  Removals removals;
  const toml::node* r = table.get("remove");
  if (!r) return removals;
  removals.at = detail::where(r->source()) + "key 'remove'";
  const std::string expected = ": expected a list of \"ARRAY.NAME\" strings, e.g. [\"walls.zone_wall_1\"]";
  const toml::array* list = r->as_array();
  if (!list) throw SceneError(removals.at + expected);
  for (const toml::node& item : *list) {
    const auto entry = item.value<std::string>();
    if (!entry) throw SceneError(removals.at + expected);
    removals.entries.push_back(*entry);
  }
  table.erase("remove");
  return removals;
}

void applyRemovals(toml::table& table, const Removals& removals) {
  for (const std::string& entry : removals.entries) {
    const std::string named = removals.at + " entry \"" + entry + "\"";
    const std::size_t dot = entry.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == entry.size())
      throw SceneError(named + ": expected ARRAY.NAME, e.g. \"walls.zone_wall_1\"");
    const std::string array_key = entry.substr(0, dot), name = entry.substr(dot + 1);
    toml::array* array = table[array_key].as_array();
    if (!array || !array->is_array_of_tables())
      throw SceneError(named + ": the scene has no array of tables [[" + array_key + "]]");
    const std::size_t idx = detail::namedEntryIndex(*array, name);
    if (idx == array->size()) {
      std::string names;
      for (const toml::node& e : *array)
        names += (names.empty() ? "" : ", ") + (*e.as_table())["name"].value_or(std::string("(unnamed)"));
      throw SceneError(named + ": no [[" + array_key + "]] entry is named '" + name + "' (names: " +
                       (names.empty() ? "none" : names) + ")");
    }
    array->erase(array->cbegin() + static_cast<std::ptrdiff_t>(idx));
  }
}

/// A scene may start with `extends = "other.toml"` (path relative to the
/// scene): it then holds only what differs from that scene, e.g. another
/// inclination, and may `remove` inherited entries of arrays of tables.
void resolveExtends(toml::table& table, const std::filesystem::path& base_dir, int depth) {
  const toml::node* e = table.get("extends");
  if (!e) {
    applyRemovals(table, takeRemovals(table));
    return;
  }
  const auto name = e->value<std::string>();
  const std::string at = detail::where(e->source()) + "key 'extends'";
  if (!name) throw SceneError(at + ": expected the file name of the scene to extend");
  if (depth > 8) throw SceneError(at + " = \"" + *name + "\": more than 8 levels (a cycle?)");
  const std::filesystem::path file = base_dir / *name;
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw SceneError(at + " = \"" + *name + "\": " + file.string() + " is a directory, not a scene file");
  std::ifstream in(file);
  if (!in) throw SceneError(at + " = \"" + *name + "\": cannot open " + file.string());
  std::stringstream buf;
  buf << in.rdbuf();
  toml::table base = parseToml(buf.str(), file.string());
  resolveExtends(base, file.parent_path(), depth + 1);
  table.erase("extends");
  const Removals removals = takeRemovals(table);
  mergeInto(base, table);
  table = std::move(base);
  applyRemovals(table, removals);
}

}  // namespace

Scene loadSceneText(const std::string& text, const std::string& source_name,
                    const std::vector<std::string>& overrides,
                    const std::filesystem::path& base_dir) {
  toml::table table = parseToml(text, source_name);
  resolveExtends(table, base_dir, 0);
  auto applied = std::make_shared<TableReader::Overrides>();
  for (const std::string& o : overrides) (*applied)[detail::applyOverride(table, o)] = o;
  Scene scene = readScene(table, base_dir, applied);
  std::ostringstream effective;
  effective << table;
  scene.text = effective.str();
  return scene;
}

namespace {

/// The text of a `kind` file ("scene", "camera"); `hint` says what to give instead of a folder.
std::string readTomlFile(const std::filesystem::path& path, const std::string& kind, const std::string& hint) {
  std::error_code ec;
  // A folder opens as an empty file on Linux: the reader would say "missing [scene]".
  if (std::filesystem::is_directory(path, ec))
    throw SceneError(path.string() + ": is a directory, not a " + kind + " file (" + hint + ")");
  std::ifstream in(path);
  if (!in) throw SceneError(path.string() + ": cannot open the " + kind + " file (does it exist?)");
  std::stringstream buf;
  buf << in.rdbuf();
  return buf.str();
}

const char* const kSceneFileHint = "give a .toml file or a built-in name";

}  // namespace

Scene loadScene(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  Scene scene = loadSceneText(readTomlFile(path, "scene", kSceneFileHint), path.string(), overrides, path.parent_path());
  scene.source = path;
  return scene;
}

std::string sceneDescription(const std::filesystem::path& path) {
  toml::table table = parseToml(readTomlFile(path, "scene", kSceneFileHint), path.string());
  resolveExtends(table, path.parent_path(), 0);
  return table["scene"]["description"].value_or(std::string());
}

namespace {

/// The [[cameras]] of a camera file's table, every key checked (SceneError naming the file).
std::vector<CameraSettings> camerasOf(const toml::table& table, const std::filesystem::path& path) {
  TableReader root(table, "");
  std::vector<CameraSettings> cameras;
  detail::readCameras(root, cameras);
  root.finish();
  if (cameras.empty()) throw SceneError(path.string() + ": no [[cameras]] table");
  return cameras;
}

toml::table parseCameraFile(const std::filesystem::path& path) {
  return parseToml(readTomlFile(path, "camera", "give a .toml file with [[cameras]]"), path.string());
}

}  // namespace

std::vector<CameraSettings> loadCameras(const std::filesystem::path& path) {
  return camerasOf(parseCameraFile(path), path);
}

std::string cameraFileOverride(const std::filesystem::path& path) {
  const toml::table table = parseCameraFile(path);
  camerasOf(table, path);  // every key checked, messages naming the file
  std::ostringstream text;
  text << *table["cameras"].as_array();  // inline tables, one a line
  std::string line;  // one line: a line break inside a value is written escaped
  bool indent = false;
  for (const char c : text.str()) {
    if (c == '\n') indent = true;
    else if (!(indent && c == ' ')) line += c, indent = false;
  }
  return "cameras=" + line;
}

std::filesystem::path builtinSceneDir() {
  return std::filesystem::path(ROCKLAB_ASSET_DIR) / "scenes";
}

std::filesystem::path resolveScene(const std::string& name_or_path) {
  const std::filesystem::path p(name_or_path);
  // A folder of that name is no scene: after `rocklab run drop --out drop` the next
  // `rocklab run drop` in the same folder means the built-in drop, not the outputs.
  std::error_code ec;
  if (std::filesystem::exists(p, ec) && !std::filesystem::is_directory(p, ec)) return p;
  if (p.extension().empty() && p.parent_path().empty()) {
    const auto builtin = builtinSceneDir() / (name_or_path + ".toml");
    if (std::filesystem::exists(builtin)) return builtin;
  }
  return p;  // loadScene reports it missing
}

}  // namespace rocklab::experiments
