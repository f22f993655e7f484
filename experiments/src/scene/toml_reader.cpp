#include "scene/toml_reader.h"

#include <charconv>
#include <cmath>
#include <mutex>
#include <sstream>

namespace rocklab::experiments::detail {

std::string numberText(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buffer[64];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
  return std::string(buffer, end);
}

namespace {
/// A value as messages print it: strings quoted, numbers as short as they read
/// back (toml++ itself prints 17 digits: -0.0040000000000000001).
std::string fmtValue(const toml::node& n) {
  std::ostringstream s;
  if (auto str = n.as_string()) s << '"' << str->get() << '"';
  else if (auto f = n.as_floating_point()) s << numberText(f->get());
  else if (n.is_table()) s << "a table";
  else if (n.is_array_of_tables()) s << "an array of tables";
  else if (auto a = n.as_array()) {
    s << '[';
    for (std::size_t k = 0; k < a->size(); ++k) s << (k ? ", " : "") << fmtValue(*a->get(k));
    s << ']';
  } else n.visit([&s](const auto& v) { s << v; });
  return s.str();
}
std::string typeName(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date/time";
  }
}
/// A finite number, integer or float; false otherwise.
bool toNumber(const toml::node& n, double& out) {
  if (auto f = n.as_floating_point()) out = f->get();
  else if (auto i = n.as_integer()) out = static_cast<double>(i->get());
  else return false;
  return std::isfinite(out);
}
/// An array of exactly 3 finite numbers; false otherwise.
bool toVec3(const toml::node& n, geometry::Vec3& out) {
  auto a = n.as_array();
  if (!a || a->size() != 3) return false;
  for (int k = 0; k < 3; ++k)
    if (!toNumber(*a->get(static_cast<std::size_t>(k)), out[k])) return false;
  return true;
}
std::string vecText(const geometry::Vec3& v) {
  return "[" + numberText(v.x()) + ", " + numberText(v.y()) + ", " + numberText(v.z()) + "]";
}
std::string quotedList(const std::vector<std::string>& allowed) {
  std::string options;
  for (const auto& a : allowed) options += (options.empty() ? "" : ", ") + ("\"" + a + "\"");
  return options;
}

/// The keys read while recording (rocklab scene-keys).
struct KeyRegistry {
  std::mutex mutex;
  bool on = false;
  std::set<KeyRead> reads;
};
KeyRegistry& keyRegistry() {
  static KeyRegistry registry;
  return registry;
}
/// While alive, the reads of `reader` are recorded as required.
struct RequiredRead {
  bool& flag;
  explicit RequiredRead(bool& f) : flag(f) { flag = true; }
  ~RequiredRead() { flag = false; }
};
}  // namespace

void recordSceneKeys(bool on) {
  KeyRegistry& r = keyRegistry();
  std::lock_guard lock(r.mutex);
  r.on = on;
  if (on) r.reads.clear();
}

std::vector<KeyRead> recordedSceneKeys() {
  KeyRegistry& r = keyRegistry();
  std::lock_guard lock(r.mutex);
  return {r.reads.begin(), r.reads.end()};
}

void TableReader::note(const std::string& key, const std::string& kind, const std::string& allowed,
                       const std::string& fallback) const {
  KeyRegistry& r = keyRegistry();
  std::lock_guard lock(r.mutex);
  if (!r.on) return;
  r.reads.insert({doc_table_, key, kind, allowed, required_read_ ? std::string() : fallback, required_read_});
}

std::string Range::describe() const {
  std::ostringstream s;
  if (std::isinf(lo) && std::isinf(hi)) return "any number";
  if (std::isinf(hi)) {
    s << (lo_open ? "> " : ">= ") << lo;
    return s.str();
  }
  if (std::isinf(lo)) {
    s << (hi_open ? "< " : "<= ") << hi;
    return s.str();
  }
  s << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
  return s.str();
}

std::string where(const toml::source_region& src) {
  std::ostringstream s;
  // No path: a node made in memory (a table a --set created; TableReader::origin
  // names the override instead).
  const std::string file = src.path ? *src.path : std::string("<scene>");
  s << file;
  if (file.rfind("--set", 0) != 0 && src.begin.line > 0) s << ':' << src.begin.line;
  s << ": ";
  return s.str();
}

TableReader::TableReader(const toml::table& table, std::string path,
                         std::shared_ptr<const Overrides> overrides)
    : table_(&table), path_(std::move(path)), label_(path_), overrides_(std::move(overrides)) {
  // The documentation table: the dotted path without array indices.
  std::stringstream parts(path_);
  std::string part;
  while (std::getline(parts, part, '.'))
    if (part.find_first_not_of("0123456789") != std::string::npos)
      doc_table_ += (doc_table_.empty() ? "" : ".") + part;
}

std::string TableReader::keyPath(const std::string& key) const {
  return label_.empty() ? key : label_ + "." + key;
}

std::string TableReader::origin(const std::string& key, const toml::source_region& src) const {
  const std::string indexed = path_.empty() ? key : path_ + "." + key;
  if (overrides_) {
    if (const auto over = overrides_->find(indexed); over != overrides_->end()) return "--set " + over->second + ": ";
    // A table only a --set made has no source: name the override inside it.
    if (!src.path)
      for (const std::string& table : {indexed, path_}) {
        if (table.empty()) continue;
        const auto inside = overrides_->lower_bound(table + ".");
        if (inside != overrides_->end() && inside->first.rfind(table + ".", 0) == 0)
          return "--set " + inside->second + ": ";
      }
  }
  return where(src);
}

void TableReader::fail(const std::string& key, const std::string& what) const {
  const toml::node* n = table_->get(key);
  const toml::source_region& src = n ? n->source() : table_->source();
  std::ostringstream s;
  s << origin(key, src);
  s << "key '" << keyPath(key) << "'";
  if (n) s << " = " << fmtValue(*n);
  s << ": " << what;
  throw SceneError(s.str());
}

bool TableReader::has(const std::string& key) const {
  note(key, "", "", "");  // asked about; its kind comes from the read that follows
  return table_->contains(key);
}

const toml::node* TableReader::node(const std::string& key) {
  used_.insert(key);
  return table_->get(key);
}

double TableReader::number(const std::string& key, double fallback, Range range) {
  note(key, "number", range.describe(), numberText(fallback));
  const toml::node* n = node(key);
  if (!n) return fallback;
  double v;
  if (auto f = n->as_floating_point()) v = f->get();
  else if (auto i = n->as_integer()) v = static_cast<double>(i->get());
  else fail(key, "expected a number, got " + typeName(*n) + "; allowed: " + range.describe());
  if (!std::isfinite(v) || !range.contains(v)) fail(key, "out of range; allowed: " + range.describe());
  return v;
}

double TableReader::requiredNumber(const std::string& key, Range range) {
  const RequiredRead required(required_read_);
  note(key, "number", range.describe(), "");
  if (!has(key)) fail(key, "missing; a number " + range.describe() + " is required");
  return number(key, 0.0, range);
}

std::int64_t TableReader::integer(const std::string& key, std::int64_t fallback, Range range) {
  note(key, "integer", range.describe(), std::to_string(fallback));
  const toml::node* n = node(key);
  if (!n) return fallback;
  auto i = n->as_integer();
  if (!i) fail(key, "expected an integer, got " + typeName(*n) + "; allowed: " + range.describe());
  if (!range.contains(static_cast<double>(i->get())))
    fail(key, "out of range; allowed: " + range.describe());
  return i->get();
}

bool TableReader::boolean(const std::string& key, bool fallback) {
  note(key, "boolean", "true, false", fallback ? "true" : "false");
  const toml::node* n = node(key);
  if (!n) return fallback;
  auto b = n->as_boolean();
  if (!b) fail(key, "expected true or false, got " + typeName(*n));
  return b->get();
}

std::string TableReader::string(const std::string& key, const std::string& fallback,
                                const std::vector<std::string>& allowed) {
  note(key, "string", quotedList(allowed), "\"" + fallback + "\"");
  const toml::node* n = node(key);
  if (!n) return fallback;
  auto s = n->as_string();
  std::string options;
  for (const auto& a : allowed) options += (options.empty() ? "" : ", ") + ("\"" + a + "\"");
  if (!s) fail(key, "expected a string, got " + typeName(*n) + (allowed.empty() ? "" : "; allowed: " + options));
  if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), s->get()) == allowed.end())
    fail(key, "not allowed; allowed: " + options);
  return s->get();
}

std::string TableReader::requiredString(const std::string& key, const std::vector<std::string>& allowed) {
  const RequiredRead required(required_read_);
  note(key, "string", quotedList(allowed), "");
  if (!has(key)) {
    std::string options;
    for (const auto& a : allowed) options += (options.empty() ? "" : ", ") + ("\"" + a + "\"");
    fail(key, "missing; a string is required" + (allowed.empty() ? "" : " (" + options + ")"));
  }
  return string(key, "", allowed);
}

geometry::Vec3 TableReader::vec3(const std::string& key, const geometry::Vec3& fallback) {
  note(key, "[x, y, z]", "", vecText(fallback));
  const toml::node* n = node(key);
  if (!n) return fallback;
  geometry::Vec3 v;
  if (!toVec3(*n, v)) fail(key, "expected an array of 3 finite numbers [x, y, z]");
  return v;
}

geometry::Vec3 TableReader::requiredVec3(const std::string& key) {
  const RequiredRead required(required_read_);
  note(key, "[x, y, z]", "", "");
  if (!has(key)) fail(key, "missing; an array of 3 numbers [x, y, z] is required");
  return vec3(key, geometry::Vec3::Zero());
}

std::vector<geometry::Vec3> TableReader::vec3List(const std::string& key) {
  note(key, "array of [x, y, z]", "", "[]");
  const toml::node* n = node(key);
  std::vector<geometry::Vec3> out;
  if (!n) return out;
  auto a = n->as_array();
  if (!a) fail(key, "expected an array of [x, y, z] arrays");
  for (const toml::node& e : *a) {
    geometry::Vec3 v;
    if (!toVec3(e, v)) fail(key, "expected an array of [x, y, z] arrays of finite numbers");
    out.push_back(v);
  }
  return out;
}

std::vector<double> TableReader::numberList(const std::string& key, Range range) {
  note(key, "array of numbers", range.describe(), "[]");
  const toml::node* n = node(key);
  std::vector<double> out;
  if (!n) return out;
  auto a = n->as_array();
  if (!a) fail(key, "expected an array of numbers " + range.describe());
  for (const toml::node& e : *a) {
    double v;
    if (!toNumber(e, v)) fail(key, "expected an array of finite numbers " + range.describe());
    if (!range.contains(v)) fail(key, "an element is out of range; allowed: " + range.describe());
    out.push_back(v);
  }
  return out;
}

std::vector<std::array<std::uint32_t, 3>> TableReader::indexTriples(const std::string& key, std::size_t count) {
  note(key, "array of [i, j, k]", "whole numbers, 0 to the vertex count - 1", "[]");
  const toml::node* n = node(key);
  std::vector<std::array<std::uint32_t, 3>> out;
  if (!n) return out;
  auto a = n->as_array();
  if (!a) fail(key, "expected an array of [i, j, k] vertex indices");
  const std::string allowed = count ? "whole numbers 0 to " + std::to_string(count - 1) + " (" +
                                          std::to_string(count) + " vertices)"
                                    : "none: there are no vertices";
  for (std::size_t row = 0; row < a->size(); ++row) {
    const auto triple = a->get(row)->as_array();
    if (!triple || triple->size() != 3)
      fail(key, "entry " + std::to_string(row) + " is not an array of 3 vertex indices [i, j, k]");
    std::array<std::uint32_t, 3>& t = out.emplace_back();
    for (std::size_t k = 0; k < 3; ++k) {
      const toml::node& e = *triple->get(k);
      double v = 0;
      const bool number = toNumber(e, v);
      if (!number || v != std::floor(v) || v < 0 || v >= static_cast<double>(count))
        fail(key, "entry " + std::to_string(row) + " [i, j, k]: " + (number ? numberText(v) : typeName(e)) +
                      " is not a vertex index; allowed: " + allowed);
      t[k] = static_cast<std::uint32_t>(v);
    }
  }
  return out;
}

std::vector<std::string> TableReader::valueTextList(const std::string& key) {
  note(key, "array of values", "", "[]");
  const toml::node* n = node(key);
  std::vector<std::string> out;
  if (!n) return out;
  auto a = n->as_array();
  if (!a) fail(key, "expected an array of values, got " + typeName(*n));
  for (const toml::node& e : *a) {
    if (e.is_table() || e.is_array_of_tables()) fail(key, "expected values, got a table");
    if (const auto f = e.as_floating_point()) {  // shortest text that reads back the same: 0.3, not 0.2999...
      char buffer[64];
      const auto end = std::to_chars(buffer, buffer + sizeof buffer, f->get()).ptr;
      std::string text(buffer, end);
      if (text.find_first_of(".eEn") == std::string::npos) text += ".0";  // stays a TOML float
      out.push_back(text);
    } else {
      out.push_back(fmtValue(e));
    }
  }
  return out;
}

std::vector<std::string> TableReader::stringList(const std::string& key, const std::vector<std::string>& allowed) {
  note(key, "array of strings", quotedList(allowed), "[]");
  const toml::node* n = node(key);
  std::vector<std::string> out;
  if (!n) return out;
  std::string options;
  for (const auto& a : allowed) options += (options.empty() ? "" : ", ") + ("\"" + a + "\"");
  auto a = n->as_array();
  if (!a) fail(key, "expected an array of strings" + (allowed.empty() ? "" : "; allowed: " + options));
  for (const toml::node& e : *a) {
    auto v = e.as_string();
    if (!v) fail(key, "expected an array of strings");
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), v->get()) == allowed.end())
      fail(key, "\"" + v->get() + "\" is not allowed; allowed: " + options);
    out.push_back(v->get());
  }
  return out;
}

std::optional<TableReader> TableReader::table(const std::string& key) {
  note(named_entries_ ? "NAME" : key, "table", "", "");
  const toml::node* n = node(key);
  if (!n) return std::nullopt;
  auto t = n->as_table();
  if (!t) fail(key, "expected a table ([" + keyPath(key) + "]), got " + typeName(*n));
  TableReader child(*t, path_.empty() ? key : path_ + "." + key, overrides_);
  child.label_ = keyPath(key);
  child.doc_table_ = (doc_table_.empty() ? "" : doc_table_ + ".") + (named_entries_ ? "NAME" : key);
  return child;
}

std::vector<TableReader> TableReader::tableArray(const std::string& key) {
  note(key, "array of tables", "", "");
  const toml::node* n = node(key);
  std::vector<TableReader> out;
  if (!n) return out;
  auto a = n->as_array();
  if (!a || !a->is_array_of_tables()) fail(key, "expected an array of tables ([[" + keyPath(key) + "]])");
  // An entry is named in messages as --set addresses it: by its `name` when no
  // other entry has that name and it reads as a key part, else by its index.
  const auto entryName = [a](std::size_t k) -> std::string {
    const auto name = a->get(k)->as_table()->get("name");
    const auto text = name ? name->value<std::string>() : std::nullopt;
    if (!text || text->empty() || text->find_first_of(". \t\"'=[]") != std::string::npos ||
        text->find_first_not_of("0123456789") == std::string::npos)
      return {};
    for (std::size_t e = 0; e < a->size(); ++e)
      if (const auto other = a->get(e)->as_table()->get("name");
          e != k && other && other->value<std::string>() == text)
        return {};
    return *text;
  };
  const std::string indexed = path_.empty() ? key : path_ + "." + key;
  for (std::size_t k = 0; k < a->size(); ++k) {
    out.emplace_back(*a->get(k)->as_table(), indexed + "." + std::to_string(k), overrides_);
    const std::string name = entryName(k);
    out.back().label_ = keyPath(key) + "." + (name.empty() ? std::to_string(k) : name);
    out.back().doc_table_ = (doc_table_.empty() ? "" : doc_table_ + ".") + key;
  }
  return out;
}

std::vector<std::string> TableReader::keys() const {
  named_entries_ = true;
  std::vector<std::string> out;
  for (const auto& [k, v] : *table_) out.emplace_back(k.str());
  return out;
}

void TableReader::finish() const {
  for (const auto& [k, v] : *table_) {
    const std::string key(k.str());
    if (used_.count(key)) continue;
    std::string allowed;
    for (const auto& u : used_) allowed += (allowed.empty() ? "" : ", ") + u;
    std::ostringstream s;
    s << origin(key, v.source());
    s << "unknown key '" << keyPath(key) << "'";
    if (!allowed.empty()) s << "; known keys here: " << allowed;
    throw SceneError(s.str());
  }
}

namespace {

/// One number of an array of numbers (`--set walls.top.corner.2=0.04`), so that a
/// sweep can vary one component of a vector as a number (and plot against it).
/// Returns `index`, the key's last part.
std::string setArrayEntry(toml::array& numbers, const std::string& index, const toml::node& value,
                          const std::string& assignment, const std::string& array_key) {
  const std::string whole = "the whole array: --set " + array_key + "=[...]";
  if (index.find_first_not_of("0123456789") != std::string::npos || index.size() > 9 ||
      std::stoul(index) >= numbers.size())
    throw SceneError("--set " + assignment + ": '" + array_key + "' is an array of " + std::to_string(numbers.size()) +
                     "; '" + index + "' must be an index into it (allowed: " +
                     (numbers.empty() ? whole : "0 to " + std::to_string(numbers.size() - 1) + ", or " + whole) + ")");
  const std::size_t i = std::stoul(index);
  if (!numbers.get(i)->is_number() || !value.is_number())
    throw SceneError("--set " + assignment + ": entry " + index + " of '" + array_key + "' is " +
                     typeName(*numbers.get(i)) + " and the value " + typeName(value) +
                     "; only a number of an array of numbers is set by index (allowed: a number, or " + whole + ")");
  if (const auto* integer = value.as_integer())
    numbers.replace(numbers.cbegin() + static_cast<std::ptrdiff_t>(i), integer->get());
  else
    numbers.replace(numbers.cbegin() + static_cast<std::ptrdiff_t>(i), *value.value<double>());
  return index;
}

}  // namespace

std::size_t namedEntryIndex(const toml::array& array, const std::string& name) {
  std::size_t idx = array.size();
  for (std::size_t e = 0; e < array.size(); ++e)
    if (const auto* entry = array.get(e)->as_table();
        entry && entry->get("name") && entry->get("name")->value<std::string>() == name)
      idx = e;
  return idx;
}

std::string applyOverride(toml::table& root, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw SceneError("--set " + assignment + ": expected key=value, e.g. --set timestep.dt=1e-6");
  // Spaces around '=' are allowed (study files write "key = value").
  const auto trim = [](std::string t) {
    const auto a = t.find_first_not_of(" \t"), b = t.find_last_not_of(" \t");
    return a == std::string::npos ? std::string() : t.substr(a, b - a + 1);
  };
  const std::string key = trim(assignment.substr(0, eq)), value = trim(assignment.substr(eq + 1));
  if (key.empty()) throw SceneError("--set " + assignment + ": expected key=value, e.g. --set timestep.dt=1e-6");
  // The value is TOML; a bare word that is not TOML is taken as a string.
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value, "--set " + key);
  } catch (const toml::parse_error&) {
    try {
      parsed = toml::parse("v = \"" + value + "\"", "--set " + key);
    } catch (const toml::parse_error&) {
      throw SceneError("--set " + assignment + ": the value is not valid TOML");
    }
  }
  // Walk the dotted path; numeric parts index arrays of tables. Every part must
  // be a name: "scene.=1" would otherwise replace [scene] itself.
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t dot = key.find('.', start);
    parts.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (parts.back().empty())
      throw SceneError("--set " + assignment + ": the key has an empty part; write TABLE.KEY=VALUE, e.g. "
                       "--set scene.end_time=0.5");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  toml::node* cur = &root;
  std::string indexed;  // the key with array indices, for the messages of the readers
  for (std::size_t k = 0; k + 1 < parts.size(); ++k) {
    if (auto t = cur->as_table()) {
      toml::node* next = t->get(parts[k]);
      if (!next) {
        t->insert(parts[k], toml::table{});
        next = t->get(parts[k]);
      }
      cur = next;
      indexed += parts[k] + ".";
    } else if (auto a = cur->as_array()) {
      // An index, or the name of an entry (walls.gate.active_until = ...).
      std::size_t idx = namedEntryIndex(*a, parts[k]);
      if (idx == a->size()) {
        if (parts[k].find_first_not_of("0123456789") != std::string::npos)
          throw SceneError("--set " + assignment + ": '" + parts[k] +
                           "' must be an index into the array or the name of one of its entries");
        idx = parts[k].size() > 9 ? a->size() : std::stoul(parts[k]);
        if (idx >= a->size())
          throw SceneError("--set " + assignment + ": index " + parts[k] + " is beyond the " +
                           std::to_string(a->size()) + " entries");
      }
      cur = a->get(idx);
      indexed += std::to_string(idx) + ".";
    } else {
      throw SceneError("--set " + assignment + ": '" + parts[k] + "' is not a table");
    }
  }
  if (toml::array* numbers = cur->as_array(); numbers && !numbers->is_array_of_tables())
    return indexed + setArrayEntry(*numbers, parts.back(), *parsed.get("v"), assignment,
                                   key.substr(0, key.rfind('.')));
  auto t = cur->as_table();
  if (!t) {
    const std::string parent = key.substr(0, key.rfind('.'));
    if (cur->is_array_of_tables())
      throw SceneError("--set " + assignment + ": '" + parent + "' is an array of tables; set a key of one entry, e.g. --set " +
                       parent + ".0.KEY=VALUE");
    throw SceneError("--set " + assignment + ": '" + parent + "' is " + typeName(*cur) + ", not a table");
  }
  // A table is changed key by key: a number or string in its place would drop
  // all of it ([[walls]] may be replaced by another array, e.g. []).
  const toml::node& new_value = *parsed.get("v");
  if (const toml::node* old = t->get(parts.back());
      old && ((old->is_table() && !new_value.is_table()) || (old->is_array_of_tables() && !new_value.is_array())))
    throw SceneError("--set " + assignment + ": '" + key + "' is a table; set one of its keys, e.g. --set " + key +
                     ".KEY=VALUE");
  t->insert_or_assign(parts.back(), new_value);
  return indexed + parts.back();
}

}  // namespace rocklab::experiments::detail
