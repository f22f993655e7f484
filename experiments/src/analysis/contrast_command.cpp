#include "analysis/contrast_command.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/csv.h"
#include "common/joined_text.h"
#include "common/json_text.h"
#include "rocklab/experiments/run.h"

namespace rocklab::experiments {

namespace {

using json = nlohmann::json;

struct ContrastError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// One figure of one variant of a set: its mean, sample standard deviation (none
/// from one sample) and the samples behind it.
struct Moments {
  double mean = NAN;
  std::optional<double> sd;
  std::size_t n = 0;
};

struct SampleSet {
  std::string label, file;
  std::vector<std::string> keys;
  std::vector<std::map<std::string, std::string>> values;  // a variant: key -> value
  std::vector<std::map<std::string, Moments>> figures;     // a variant: figure -> its moments (numbers only)
  std::vector<std::string> figure_order;                   // as the first variant lists them
};

std::string valueText(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

SampleSet readSet(const std::filesystem::path& dir, const std::string& label) {
  SampleSet s;
  s.label = label;
  s.file = (dir / "samples.json").string();
  std::ifstream in(s.file);
  if (!in) throw ContrastError(s.file + ": not found (allowed: a folder written by `rocklab samples`)");
  json j;
  try {
    j = json::parse(in);
    for (const json& k : j.at("keys")) s.keys.push_back(k.get<std::string>());
    for (const json& v : j.at("variants")) {
      std::map<std::string, std::string> values;
      for (const auto& [k, x] : v.at("values").items()) values[k] = valueText(x);
      std::map<std::string, Moments> figures;
      for (const auto& [name, f] : v.at("figures").items()) {
        if (!f.contains("mean")) continue;  // flags and text have no mean
        if (s.values.empty()) s.figure_order.push_back(name);
        Moments m;
        m.n = f.at("n").get<std::size_t>();
        if (!f.at("mean").is_null()) m.mean = f.at("mean").get<double>();
        if (!f.at("sd").is_null()) m.sd = f.at("sd").get<double>();
        figures[name] = m;
      }
      s.values.push_back(values);
      s.figures.push_back(figures);
    }
  } catch (const json::exception& e) {
    throw ContrastError(s.file + ": not a samples.json of `rocklab samples` (" + e.what() + ")");
  }
  return s;
}

/// Keeps the variants of `s` that have each `where` value for the keys it varies.
void applyWhere(SampleSet& s, const std::vector<std::pair<std::string, std::string>>& where) {
  std::vector<std::map<std::string, std::string>> values;
  std::vector<std::map<std::string, Moments>> figures;
  for (std::size_t v = 0; v < s.values.size(); ++v) {
    const bool kept = std::all_of(where.begin(), where.end(), [&](const auto& w) {
      const auto it = s.values[v].find(w.first);
      return it == s.values[v].end() || it->second == w.second;
    });
    if (!kept) continue;
    values.push_back(s.values[v]);
    figures.push_back(s.figures[v]);
  }
  s.values = std::move(values);
  s.figures = std::move(figures);
}

std::string tupleText(const std::vector<std::string>& keys, const std::map<std::string, std::string>& values) {
  std::vector<std::string> parts;
  for (const std::string& k : keys) parts.push_back(k + " = " + values.at(k));
  return detail::joinedText(parts, ", ");
}

/// Each variant of `s` by its values of the common keys; two alike are refused.
std::map<std::vector<std::string>, std::size_t> byCommonKeys(const SampleSet& s, const std::vector<std::string>& common) {
  std::map<std::vector<std::string>, std::size_t> index;
  for (std::size_t v = 0; v < s.values.size(); ++v) {
    std::vector<std::string> tuple;
    for (const std::string& k : common) tuple.push_back(s.values[v].at(k));
    if (!index.emplace(tuple, v).second) {
      std::vector<std::string> others;
      for (const std::string& k : s.keys)
        if (std::find(common.begin(), common.end(), k) == common.end()) others.push_back(k);
      throw ContrastError(s.file + ": two variants with " + tupleText(common, s.values[v]) +
                          ": fix what only this set varies with --where KEY=VALUE (its keys: " +
                          detail::joinedText(others, ", ") + ")");
    }
  }
  return index;
}

/// x to `digits` significant digits; `none` when it is not finite.
std::string text(double x, int digits, const char* none) {
  if (!std::isfinite(x)) return none;
  std::ostringstream o;
  o.precision(digits);
  o << x;
  return o.str();
}
std::string number(double x) { return text(x, 6, ""); }    // the CSV's
std::string rounded(double x) { return text(x, 3, "–"); }  // the Markdown's

struct Contrasted {
  double value = NAN;
  std::optional<double> scatter;  // none when either side has one sample
};

Contrasted contrast(ContrastOp op, const Moments& a, const Moments& b) {
  Contrasted c;
  if (op == ContrastOp::Ratio) {
    c.value = a.mean / b.mean;
    if (a.sd && b.sd) c.scatter = std::abs(c.value) * std::hypot(*a.sd / a.mean, *b.sd / b.mean);
  } else {
    c.value = a.mean - b.mean;
    if (a.sd && b.sd) c.scatter = std::hypot(*a.sd, *b.sd);
  }
  if (!std::isfinite(c.value)) c.scatter.reset();
  return c;
}

}  // namespace

int runContrastCommand(const ContrastOptions& o, std::ostream& out, std::ostream& err) {
  const auto& dirs = o.sets.runs;
  const char* op_name = o.op == ContrastOp::Ratio ? "ratio" : "difference";
  SampleSet a, b;
  std::vector<std::string> common, figures;
  std::vector<std::pair<std::string, std::string>> where;
  std::vector<std::pair<std::size_t, std::size_t>> matched;  // (variant of A, of B)
  std::vector<std::string> unmatched;
  try {
    if (dirs.size() != 2)
      throw ContrastError(std::to_string(dirs.size()) + " folder(s) given (allowed: two, A then B)");
    if (const std::string problem = detail::runLabelsProblem(dirs.size(), o.sets.labels.size()); !problem.empty())
      throw ContrastError(problem);
    a = readSet(dirs[0], detail::runLabel(dirs, o.sets.labels, 0));
    b = readSet(dirs[1], detail::runLabel(dirs, o.sets.labels, 1));
    for (const std::string& k : a.keys)
      if (std::find(b.keys.begin(), b.keys.end(), k) != b.keys.end()) common.push_back(k);
    if (common.empty())
      throw ContrastError("no varied key in common: " + a.file + " varies " + detail::joinedText(a.keys, ", ") +
                          ", " + b.file + " varies " + detail::joinedText(b.keys, ", "));
    for (const std::string& w : o.where) {
      const auto eq = w.find('=');
      if (eq == std::string::npos || eq == 0)
        throw ContrastError("--where " + w + ": not KEY=VALUE");
      const std::string key = w.substr(0, eq), value = w.substr(eq + 1);
      const SampleSet* owner = nullptr;
      for (const SampleSet* s : {&a, &b})
        if (std::find(s->keys.begin(), s->keys.end(), key) != s->keys.end()) owner = s;
      if (!owner)
        throw ContrastError("--where " + w + ": neither set varies " + key + " (allowed: " +
                            detail::joinedText(a.keys, ", ") + "; " + detail::joinedText(b.keys, ", ") + ")");
      std::vector<std::string> have;
      for (const SampleSet* s : {&a, &b})
        for (const auto& v : s->values)
          if (const auto it = v.find(key); it != v.end() && std::find(have.begin(), have.end(), it->second) == have.end())
            have.push_back(it->second);
      if (std::find(have.begin(), have.end(), value) == have.end())
        throw ContrastError("--where " + w + ": no variant has " + key + " = " + value + " (allowed: " +
                            detail::joinedText(have, ", ") + ")");
      where.emplace_back(key, value);
    }
    applyWhere(a, where);
    applyWhere(b, where);
    const auto a_index = byCommonKeys(a, common), b_index = byCommonKeys(b, common);
    for (std::size_t v = 0; v < a.values.size(); ++v) {
      std::vector<std::string> tuple;
      for (const std::string& k : common) tuple.push_back(a.values[v].at(k));
      if (const auto it = b_index.find(tuple); it != b_index.end())
        matched.emplace_back(v, it->second);
      else
        unmatched.push_back(a.label + ": " + tupleText(common, a.values[v]));
    }
    for (const auto& [tuple, v] : b_index)
      if (!a_index.count(tuple)) unmatched.push_back(b.label + ": " + tupleText(common, b.values[v]));
    for (const std::string& f : a.figure_order)
      if (std::find(b.figure_order.begin(), b.figure_order.end(), f) != b.figure_order.end()) figures.push_back(f);
    if (matched.empty()) throw ContrastError("no variant of " + a.file + " matches one of " + b.file + " on " +
                                             detail::joinedText(common, ", "));
  } catch (const ContrastError& e) {
    err << "error: contrast: " << e.what() << '\n';
    return kExitBadInput;
  }

  std::ostringstream csv, md;
  for (const std::string& k : common) csv << detail::csvCell(k) << ',';
  for (std::size_t f = 0; f < figures.size(); ++f)
    for (const char* s : {".value", ".scatter", ".n_a", ".n_b"})
      csv << (f || s != std::string(".value") ? "," : "") << detail::csvCell(figures[f] + s);
  csv << '\n';
  md << "| " << detail::joinedText(common, " | ");
  for (const std::string& f : figures) md << " | " << f;
  md << " |\n|";
  for (std::size_t k = 0; k < common.size() + figures.size(); ++k) md << "---|";
  md << '\n';
  json rows = json::array();
  for (const auto& [va, vb] : matched) {
    json row = {{"values", json::object()}, {"figures", json::object()}};
    md << '|';
    for (const std::string& k : common) {
      csv << detail::csvCell(a.values[va].at(k)) << ',';
      md << ' ' << a.values[va].at(k) << " |";
      row["values"][k] = a.values[va].at(k);
    }
    for (std::size_t f = 0; f < figures.size(); ++f) {
      const Moments& ma = a.figures[va].at(figures[f]);
      const Moments& mb = b.figures[vb].at(figures[f]);
      const Contrasted c = contrast(o.op, ma, mb);
      csv << (f ? "," : "") << number(c.value) << ',' << (c.scatter ? number(*c.scatter) : "") << ',' << ma.n << ','
          << mb.n;
      md << ' ' << rounded(c.value) << (c.scatter ? " ± " + rounded(*c.scatter) : "") << " (" << ma.n << ", "
         << mb.n << ") |";
      const auto side = [](const Moments& m) {
        return json{{"mean", detail::finiteOrNull(m.mean)}, {"sd", m.sd ? json(*m.sd) : json()}, {"n", m.n}};
      };
      row["figures"][figures[f]] = {{"value", detail::finiteOrNull(c.value)},
                                    {"scatter", c.scatter ? json(*c.scatter) : json()},
                                    {"a", side(ma)},
                                    {"b", side(mb)}};
    }
    csv << '\n';
    md << '\n';
    rows.push_back(row);
  }
  json where_json = json::object();
  for (const auto& [k, v] : where) where_json[k] = v;
  const json summary = {
      {"a", {{"label", a.label}, {"samples", a.file}}},
      {"b", {{"label", b.label}, {"samples", b.file}}},
      {"op", op_name},
      {"where", where_json},
      {"keys", common},
      {"method", o.op == ContrastOp::Ratio
                     ? "value = mean_A / mean_B; scatter = |value| sqrt((sd_A / mean_A)^2 + (sd_B / mean_B)^2), the "
                       "sample standard deviations over each set's samples; none when a side has one sample"
                     : "value = mean_A - mean_B; scatter = sqrt(sd_A^2 + sd_B^2), the sample standard deviations "
                       "over each set's samples; none when a side has one sample"},
      {"variants", rows},
      {"unmatched", unmatched}};
  try {
    std::filesystem::create_directories(o.sets.out_dir);
    detail::writeAtomically(o.sets.out_dir / "contrast.csv", csv.str());
    detail::writeAtomically(o.sets.out_dir / "contrast.json", detail::jsonText(summary));
    detail::writeAtomically(o.sets.out_dir / "contrast.md", md.str());
  } catch (const std::exception& e) {
    err << "error: contrast: " << e.what() << '\n';
    return kExitFailed;
  }
  out << op_name << " of " << a.label << " to " << b.label << " (value ± scatter (n_A, n_B)):\n" << md.str();
  for (const std::string& u : unmatched) out << "note: no partner for " << u << '\n';
  out << "wrote " << (o.sets.out_dir / "contrast.csv").string() << ", contrast.json, contrast.md\n";
  return 0;
}

}  // namespace rocklab::experiments
