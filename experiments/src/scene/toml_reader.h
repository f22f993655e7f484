#pragma once
// Checked access to a TOML table: every read names its key, type and range, and
// finish() rejects keys that nobody read (pbrt's "unused parameter" rule).
#include <toml++/toml.h>

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "rocklab/experiments/scene.h"
#include "rocklab/geometry/vec.h"

namespace rocklab::experiments::detail {

/// An interval of allowed values, printed in messages as e.g. "(0, 1]".
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static Range nonNegative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
  static Range closed(double a, double b) { return {a, b, false, false}; }
  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  std::string describe() const;
};

/// One key as a reader asked for it (rocklab scene-keys): the documentation
/// table it belongs to ("materials.NAME", "walls", "experiment.chute"), its name,
/// what kind of value it takes, the values allowed, its default as TOML text and
/// whether it is required. Recorded only while recordSceneKeys(true).
struct KeyRead {
  std::string table, key, kind, allowed, fallback;
  bool required = false;
  auto operator<=>(const KeyRead&) const = default;
};
/// Starts (clearing what was recorded) or stops recording every key read.
void recordSceneKeys(bool on);
/// Every distinct key read since recording started.
std::vector<KeyRead> recordedSceneKeys();

class TableReader {
 public:
  /// Dotted key with array indices ("cameras.0.resolution", as applyOverride
  /// returns it) -> the --set assignment that gave it (messages then name the override).
  using Overrides = std::map<std::string, std::string>;
  /// `path` is the dotted key of this table ("" for the root), with array indices.
  TableReader(const toml::table& table, std::string path,
              std::shared_ptr<const Overrides> overrides = nullptr);

  bool has(const std::string& key) const;
  double number(const std::string& key, double fallback, Range range = {});
  double requiredNumber(const std::string& key, Range range = {});
  std::int64_t integer(const std::string& key, std::int64_t fallback, Range range = {});
  bool boolean(const std::string& key, bool fallback);
  std::string string(const std::string& key, const std::string& fallback,
                     const std::vector<std::string>& allowed = {});
  std::string requiredString(const std::string& key, const std::vector<std::string>& allowed = {});
  /// A string key that names one of a fixed set of values: `options` pairs each value
  /// with its name, the allowed strings; `fallback`'s name is the default.
  template <class Value>
  Value choice(const std::string& key, Value fallback, const std::vector<std::pair<Value, std::string>>& options) {
    std::vector<std::string> names;
    std::string fallback_name;
    for (const auto& [value, name] : options) {
      names.push_back(name);
      if (value == fallback) fallback_name = name;
    }
    const std::string read = string(key, fallback_name, names);
    for (const auto& [value, name] : options)
      if (name == read) return value;
    return fallback;
  }
  geometry::Vec3 vec3(const std::string& key, const geometry::Vec3& fallback);
  geometry::Vec3 requiredVec3(const std::string& key);
  std::vector<geometry::Vec3> vec3List(const std::string& key);
  std::vector<double> numberList(const std::string& key, Range range = {});
  /// An array of [i, j, k] index triples, each a whole number in [0, count) (mesh
  /// triangles into `count` vertices).
  std::vector<std::array<std::uint32_t, 3>> indexTriples(const std::string& key, std::size_t count);
  std::vector<std::string> stringList(const std::string& key, const std::vector<std::string>& allowed = {});
  /// An array of any TOML values, each as TOML text ("0.5", "\"linear\"", "[960, 400]"),
  /// the form --set takes.
  std::vector<std::string> valueTextList(const std::string& key);
  std::optional<TableReader> table(const std::string& key);
  std::vector<TableReader> tableArray(const std::string& key);
  /// Names of all keys of this table (for tables of named entries).
  std::vector<std::string> keys() const;

  /// Throws for the first key that was never read.
  void finish() const;

  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  /// Dotted key as messages name it: an entry of an array of tables by its
  /// `name` when it has a unique one ("cameras.side.resolution"), else by index.
  std::string keyPath(const std::string& key) const;
  /// Dotted key of this table with array indices, e.g. "walls.2".
  const std::string& path() const { return path_; }
  const toml::table& raw() const { return *table_; }
  /// The documentation table of the keys read from now on (default: the dotted
  /// path with array indices dropped, e.g. "walls"); the experiment reader sets
  /// "experiment.TYPE" before the driver reads its keys.
  void setDocTable(std::string table) { doc_table_ = std::move(table); }
  const std::string& docTable() const { return doc_table_; }

 private:
  const toml::node* node(const std::string& key);
  /// Where a message about `key` points: "--set ASSIGNMENT: " when an override
  /// gave the key (or made the table it sits in), else "file:line: " of `src`.
  std::string origin(const std::string& key, const toml::source_region& src) const;
  /// Records a key read (when recording) under doc_table_.
  void note(const std::string& key, const std::string& kind, const std::string& allowed,
            const std::string& fallback) const;
  /// Set while a required...() read runs: its key is recorded as required.
  bool required_read_ = false;
  /// keys() was asked: the sub-tables are named entries (doc table "TABLE.NAME").
  mutable bool named_entries_ = false;
  std::string doc_table_;
  const toml::table* table_;
  std::string path_;
  /// What messages call this table (path_ with named entries by name).
  std::string label_;
  std::set<std::string> used_;
  std::shared_ptr<const Overrides> overrides_;
};

/// "file:line: " for a node.
std::string where(const toml::source_region& src);
/// The index of the entry of an array of tables whose `name` is `name` (the last
/// such entry), or array.size() when none is: how `--set walls.gate.x=...` and
/// `remove = ["walls.gate"]` find an entry.
std::size_t namedEntryIndex(const toml::array& array, const std::string& name);
/// Sets `key.path=value` in `root`; throws SceneError naming the override.
/// Returns the dotted key with array indices (walls.gate.x -> walls.2.x). A
/// last part that is an index into an array of numbers sets that number
/// (walls.top.corner.2=0.04).
std::string applyOverride(toml::table& root, const std::string& assignment);
/// The shortest text that reads back as `v` ("0.3", "-0.004", "1e-06", "inf"):
/// messages print what the user wrote, not 17 digits.
std::string numberText(double v);

}  // namespace rocklab::experiments::detail
