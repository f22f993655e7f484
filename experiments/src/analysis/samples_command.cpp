#include "analysis/samples_command.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "analysis/plot.h"
#include "analysis/sample_statistics.h"
#include "analysis/sweep_sets.h"
#include "analysis/sweep_table.h"
#include "common/atomic_file.h"
#include "common/csv.h"
#include "common/joined_text.h"
#include "common/json_text.h"
#include "rocklab/experiments/run.h"
#include "scene/scene_keys.h"
#include "sets/run_set.h"

namespace rocklab::experiments {

namespace {

using json = nlohmann::json;

using detail::figureColumns;
using SampleSet = detail::SweepSet;  // a sweep a sample (or, with `over`, several)
using SamplesInputError = detail::SweepSetError;

enum class FigureKind { Number, Flag, Text };

bool isFlag(const std::string& cell) { return cell == "true" || cell == "false"; }

/// What a figure's cells hold over every variant and sample (empty cells aside).
FigureKind kindOf(const std::vector<std::vector<std::optional<std::string>>>& cells) {
  bool numbers = true, flags = true;
  for (const auto& variant : cells)
    for (const auto& c : variant) {
      if (!c || c->empty()) continue;
      numbers = numbers && SweepTable::numberIn({*c}, 0).has_value();
      flags = flags && isFlag(*c);
    }
  if (numbers) return FigureKind::Number;  // also when every cell is empty
  return flags ? FigureKind::Flag : FigureKind::Text;
}

struct Statistics {
  std::size_t n = 0, true_count = 0;
  double mean = NAN, sd = NAN, min = NAN, max = NAN;  // sd: sample standard deviation (n - 1)
  std::vector<std::string> texts;                     // distinct, for text figures
};

Statistics statisticsOf(FigureKind kind, const std::vector<std::optional<std::string>>& cells) {
  Statistics st;
  std::vector<double> v;
  for (const auto& c : cells) {
    if (!c || c->empty()) continue;
    ++st.n;
    if (kind == FigureKind::Number) v.push_back(*SweepTable::numberIn({*c}, 0));
    if (kind == FigureKind::Flag) st.true_count += *c == "true";
    if (kind == FigureKind::Text && std::find(st.texts.begin(), st.texts.end(), *c) == st.texts.end())
      st.texts.push_back(*c);
  }
  const SampleStatistics s = sampleStatistics(v);
  st.mean = s.mean;
  st.sd = s.sd;
  st.min = s.min;
  st.max = s.max;
  return st;
}


/// A cell as samples.json gives it: a number, true/false, text, or null (empty or no run).
json cellJson(FigureKind kind, const std::optional<std::string>& c) {
  if (!c || c->empty()) return json();
  if (kind == FigureKind::Number) return *SweepTable::numberIn({*c}, 0);
  if (kind == FigureKind::Flag) return *c == "true";
  return *c;
}

/// The merged table: variants in the order the first sample's table lists them
/// (then any only later samples ran), each figure's cells a sample.
struct Merged {
  std::vector<std::string> keys, figures;                                   // keys: the varied ones but `over`
  std::string x_over;  // the sets' --x-over: the plot's x is the first set key's value over this figure's mean
  std::vector<std::string> sample_labels;                                   // a sample
  std::vector<std::size_t> sample_set;                                      // its set
  std::vector<std::vector<std::string>> variants;                           // values in `keys` order
  std::vector<std::size_t> rows;                                            // samples with a row
  std::vector<std::vector<std::vector<std::optional<std::string>>>> cells;  // [figure][variant][sample]
  std::vector<FigureKind> kinds;                                            // a figure
  std::vector<std::vector<Statistics>> stats;                               // [figure][variant]
};

/// A sample a set, or with `over` (a varied key) a sample a value of it in each set.
Merged merge(const std::vector<SampleSet>& sets, const std::string& over) {
  Merged m;
  for (const std::string& k : sets.front().keys)
    if (k != over) m.keys.push_back(k);
  // The sweeps' x over a figure needs their first key (not the one merged over).
  if (sets.front().keys.front() != over) m.x_over = sets.front().x_over;
  m.figures = figureColumns(sets.front());
  // The samples first (the cells are sized by them): the sets in order, each set's values
  // of `over` in the order of its table.
  std::vector<std::map<std::string, std::size_t>> sample_of(sets.size());  // [set][value of over]
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const SweepTable& t = sets[s].table;
    const std::size_t over_column = over.empty() ? 0 : t.column(over);
    for (const std::vector<std::string>& row : t.rows) {
      const std::string value = over.empty() || over_column >= row.size() ? std::string() : row[over_column];
      if (!sample_of[s].emplace(value, m.sample_labels.size()).second) continue;
      m.sample_labels.push_back(over.empty()   ? sets[s].label
                                : sets.size() > 1 ? sets[s].label + ", " + over + " = " + value
                                                  : over + " = " + value);
      m.sample_set.push_back(s);
    }
    if (t.rows.empty() && over.empty()) {  // a set whose every run failed is still a sample
      sample_of[s].emplace("", m.sample_labels.size());
      m.sample_labels.push_back(sets[s].label);
      m.sample_set.push_back(s);
    }
  }
  const std::size_t samples = m.sample_labels.size();
  std::map<std::vector<std::string>, std::size_t> index;
  std::vector<std::vector<bool>> seen;  // [variant][sample]
  m.cells.assign(m.figures.size(), {});
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const SweepTable& t = sets[s].table;
    std::vector<std::size_t> key_columns, figure_columns;
    for (const std::string& k : m.keys) key_columns.push_back(t.column(k));
    for (const std::string& f : m.figures) figure_columns.push_back(t.column(f));
    const std::size_t over_column = over.empty() ? 0 : t.column(over);
    for (const std::vector<std::string>& row : t.rows) {
      std::vector<std::string> values;
      for (std::size_t c : key_columns) values.push_back(c < row.size() ? row[c] : "");
      auto [it, added] = index.emplace(values, m.variants.size());
      if (added) {
        m.variants.push_back(values);
        m.rows.push_back(0);
        seen.emplace_back(samples, false);
        for (auto& figure : m.cells) figure.emplace_back(samples);
      }
      const std::size_t v = it->second;
      const std::size_t sample =
          sample_of[s].at(over.empty() || over_column >= row.size() ? std::string() : row[over_column]);
      if (seen[v][sample]) continue;  // a variant twice in one sample: its first row
      seen[v][sample] = true;
      ++m.rows[v];
      for (std::size_t f = 0; f < figure_columns.size(); ++f)
        m.cells[f][v][sample] = figure_columns[f] < row.size() ? row[figure_columns[f]] : std::string();
    }
  }
  for (const auto& figure : m.cells) {
    m.kinds.push_back(kindOf(figure));
    std::vector<Statistics>& per_variant = m.stats.emplace_back();
    for (const auto& cells : figure) per_variant.push_back(statisticsOf(m.kinds.back(), cells));
  }
  return m;
}

std::string formatted(double v) { return detail::cell(detail::finiteOrNull(v)); }

/// A number to `digits` significant digits (NaN: "-").
std::string significant(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  // Whole from `digits` digits before the point (4366, not 4.37e+03; 29, not 29.), else with
  // its trailing zeros (1.00, not 1).
  if (std::abs(v) >= std::pow(10.0, digits - 1)) s << std::fixed << std::setprecision(0) << v;
  else s << std::showpoint << std::setprecision(digits) << v;
  return s.str();
}

/// samples.md: the table as a report takes it, a row a variant: a number's mean ± sample
/// sd (n) to three digits, a true/false figure's count of true out of n, text as it is.
std::string markdownTable(const Merged& m) {
  const auto escaped = [](std::string text) {
    for (std::size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2)) text.insert(at, "\\");
    return text;
  };
  std::ostringstream md;
  md << '|';
  for (const std::string& k : m.keys) md << ' ' << escaped(k) << " |";
  md << " samples |";
  for (const std::string& f : m.figures) md << ' ' << escaped(f) << " |";
  md << "\n|";
  for (std::size_t c = 0; c < m.keys.size() + 1 + m.figures.size(); ++c) md << "---|";
  md << '\n';
  for (std::size_t v = 0; v < m.variants.size(); ++v) {
    md << '|';
    for (const std::string& value : m.variants[v]) md << ' ' << escaped(value) << " |";
    md << ' ' << m.rows[v] << " |";
    for (std::size_t f = 0; f < m.figures.size(); ++f) {
      const Statistics& st = m.stats[f][v];
      md << ' ';
      switch (m.kinds[f]) {
        case FigureKind::Number:
          if (st.n == 0) md << "- (0)";
          else md << significant(st.mean, 3) << (st.n > 1 ? " ± " + significant(st.sd, 2) : "") << " (" << st.n << ')';
          break;
        case FigureKind::Flag: md << st.true_count << '/' << st.n; break;
        case FigureKind::Text: md << escaped(detail::joinedText(st.texts, "; ")); break;
      }
      md << " |";
    }
    md << '\n';
  }
  md << "\nmean ± sample standard deviation (number of samples that have the figure); true/false figures: "
        "true out of n\n";
  return md.str();
}

/// samples.png: the figure against the first varied key whose values are all numbers
/// (else the variant's row), a group a combination of the other keys; each sample a
/// point, the mean a line where every sample has the figure. Sweeps made with
/// --x-over plot against their first key's value over that figure's mean in the variant.
PlotSpec samplesPlot(const Merged& m, std::size_t figure, std::size_t samples) {
  std::optional<std::size_t> x_key;
  for (std::size_t k = 0; k < m.keys.size() && !x_key; ++k) {
    bool all = true;
    for (const auto& values : m.variants) all = all && SweepTable::numberIn(values, k).has_value();
    if (all) x_key = k;
  }
  std::optional<std::size_t> divisor;  // the --x-over figure
  if (!m.x_over.empty() && x_key == 0)
    for (std::size_t f = 0; f < m.figures.size(); ++f)
      if (m.figures[f] == m.x_over && m.kinds[f] == FigureKind::Number) divisor = f;
  PlotSpec spec;
  spec.title = m.figures[figure] + " over " + std::to_string(samples) +
               " samples: each sample a point, the mean a line where every sample has it";
  spec.x_label = !x_key     ? "variant (row of samples.csv)"
                 : divisor ? m.keys[*x_key] + " / " + m.x_over
                           : withSceneKeyUnit(m.keys[*x_key]);
  spec.y_label = m.figures[figure];
  std::map<std::string, std::vector<std::size_t>> groups;  // by the other keys' values
  std::vector<std::string> group_order;
  for (std::size_t v = 0; v < m.variants.size(); ++v) {
    std::string group;
    for (std::size_t k = 0; k < m.keys.size(); ++k)
      if (!x_key || k != *x_key) group += (group.empty() ? "" : ", ") + m.keys[k] + " = " + m.variants[v][k];
    if (!x_key) group.clear();  // no numeric key: one series, the variants in a row
    if (groups[group].empty()) group_order.push_back(group);
    groups[group].push_back(v);
  }
  for (std::size_t g = 0; g < group_order.size(); ++g) {
    const std::string& name = group_order[g];
    std::vector<std::size_t> members = groups[name];
    const auto xOf = [&](std::size_t v) {
      if (!x_key) return static_cast<double>(v + 1);
      const double x = *SweepTable::numberIn(m.variants[v], *x_key);
      return divisor ? x / m.stats[*divisor][v].mean : x;  // no sample has the divisor: NaN, no point
    };
    std::sort(members.begin(), members.end(), [&](std::size_t a, std::size_t b) {
      const double xa = xOf(a), xb = xOf(b);
      return std::isnan(xb) ? !std::isnan(xa) : xa < xb;  // a variant without an x last
    });
    PlotSeries points{name.empty() ? "each sample" : name + ": each sample", {}, {}, PlotSeries::Style::Points};
    PlotSeries mean{name.empty() ? "mean" : name + ": mean", {}, {}, PlotSeries::Style::LinePoints};
    for (std::size_t v : members) {
      const auto& cells = m.cells[figure][v];
      std::size_t have = 0;
      for (const auto& c : cells)
        if (const auto y = c ? SweepTable::numberIn({*c}, 0) : std::nullopt) {
          points.x.push_back(xOf(v));
          points.y.push_back(*y);
          ++have;
        }
      mean.x.push_back(xOf(v));
      mean.y.push_back(have == samples ? m.stats[figure][v].mean : NAN);  // a line break where a sample has none
    }
    if (points.x.empty()) continue;  // no sample has the figure (every case jammed): no empty legend entry
    points.colour = mean.colour = static_cast<int>(g);
    spec.series.push_back(points);
    spec.series.push_back(mean);
  }
  return spec;
}

}  // namespace

int runSamplesCommand(const RunComparisonOptions& o, const std::string& figure_name, const std::string& over,
                      std::ostream& out, std::ostream& err) {
  if (const std::string problem = detail::runLabelsProblem(o.runs.size(), o.labels.size()); !problem.empty()) {
    err << "error: samples: " << problem << "\n";
    return kExitBadInput;
  }
  std::vector<SampleSet> sets;
  Merged m;
  std::optional<std::size_t> figure;
  try {
    for (std::size_t k = 0; k < o.runs.size(); ++k) {
      sets.push_back(detail::readSweepSet(o.runs[k]));
      sets.back().label = detail::runLabel(o.runs, o.labels, k);
    }
    detail::checkSameShape(sets, "one a sample");
    const std::vector<std::string>& keys = sets.front().keys;
    if (!over.empty() && std::find(keys.begin(), keys.end(), over) == keys.end())
      throw SamplesInputError("--over " + over + ": not a key " + (sets.front().dir / "plan.json").string() +
                              " varies (allowed: " + detail::sortedNames(keys) + ")");
    m = merge(sets, over);
    for (std::size_t f = 0; f < m.figures.size(); ++f) {
      const bool any = std::any_of(m.cells[f].begin(), m.cells[f].end(), [](const auto& variant) {
        return std::any_of(variant.begin(), variant.end(), [](const auto& c) { return c && !c->empty(); });
      });
      if (figure_name.empty() ? (m.kinds[f] == FigureKind::Number && any && !figure) : m.figures[f] == figure_name)
        figure = f;
    }
    if (!figure_name.empty() && (!figure || m.kinds[*figure] != FigureKind::Number))
      throw SamplesInputError("--figure " + figure_name + ": " +
                              (figure ? "not numbers in " : "not a column of ") + sets.front().table.file.string() +
                              " (allowed: a figure column with numbers: " + [&] {
                                std::vector<std::string> allowed;
                                for (std::size_t f = 0; f < m.figures.size(); ++f)
                                  if (m.kinds[f] == FigureKind::Number) allowed.push_back(m.figures[f]);
                                return detail::sortedNames(allowed);
                              }() + ")");
  } catch (const SamplesInputError& e) {
    err << "error: samples: " << e.what() << '\n';
    return kExitBadInput;
  }

  // samples.csv and samples.json: a row a variant.
  std::ostringstream csv;
  for (const std::string& k : m.keys) csv << detail::csvCell(k) << ',';
  csv << "samples";
  for (std::size_t f = 0; f < m.figures.size(); ++f) {
    const std::string& name = m.figures[f];
    switch (m.kinds[f]) {
      case FigureKind::Number:
        for (const char* s : {".mean", ".sd", ".min", ".max", ".n"}) csv << ',' << detail::csvCell(name + s);
        break;
      case FigureKind::Flag: csv << ',' << detail::csvCell(name + ".true") << ',' << detail::csvCell(name + ".n"); break;
      case FigureKind::Text: csv << ',' << detail::csvCell(name + ".values"); break;
    }
  }
  csv << '\n';
  json variants = json::array();
  for (std::size_t v = 0; v < m.variants.size(); ++v) {
    json row = {{"values", json::object()}, {"samples", m.rows[v]}, {"figures", json::object()}};
    for (std::size_t k = 0; k < m.keys.size(); ++k) {
      csv << detail::csvCell(m.variants[v][k]) << ',';
      row["values"][m.keys[k]] = m.variants[v][k];
    }
    csv << m.rows[v];
    for (std::size_t f = 0; f < m.figures.size(); ++f) {
      const Statistics& st = m.stats[f][v];
      json entry = {{"n", st.n}, {"per_sample", json::array()}};
      for (const auto& c : m.cells[f][v]) entry["per_sample"].push_back(cellJson(m.kinds[f], c));
      switch (m.kinds[f]) {
        case FigureKind::Number:
          csv << ',' << formatted(st.mean) << ',' << formatted(st.sd) << ',' << formatted(st.min) << ','
              << formatted(st.max) << ',' << st.n;
          entry.update({{"mean", detail::finiteOrNull(st.mean)}, {"sd", detail::finiteOrNull(st.sd)}, {"min", detail::finiteOrNull(st.min)},
                        {"max", detail::finiteOrNull(st.max)}});
          break;
        case FigureKind::Flag:
          csv << ',' << st.true_count << ',' << st.n;
          entry["true"] = st.true_count;
          break;
        case FigureKind::Text: {
          csv << ',' << detail::csvCell(detail::joinedText(st.texts, "; "));
          entry["values"] = st.texts;
          break;
        }
      }
      row["figures"][m.figures[f]] = entry;
    }
    csv << '\n';
    variants.push_back(row);
  }
  json set_list = json::array(), samples = json::array();
  for (const SampleSet& s : sets)
    set_list.push_back({{"label", s.label}, {"sweep", s.dir.string()}, {"runs_not_ok", s.table.not_ok}});
  for (std::size_t k = 0; k < m.sample_labels.size(); ++k)
    samples.push_back({{"label", m.sample_labels[k]}, {"set", m.sample_set[k]}});
  const json summary = {{"sets", set_list},
                        {"samples", samples},
                        {"over", over.empty() ? json() : json(over)},
                        {"keys", m.keys},
                        {"statistics", "mean, sample standard deviation (n - 1), min, max over the samples that have "
                                       "the figure (n); true/false figures: how many of n are true"},
                        {"variants", variants}};
  try {
    std::filesystem::create_directories(o.out_dir);
    detail::writeAtomically(o.out_dir / "samples.csv", csv.str());
    detail::writeAtomically(o.out_dir / "samples.json", detail::jsonText(summary));
    detail::writeAtomically(o.out_dir / "samples.md", markdownTable(m));
    if (figure) writePlot(samplesPlot(m, *figure, m.sample_labels.size()), o.out_dir / "samples.png");
  } catch (const std::exception& e) {
    err << "error: samples: " << e.what() << '\n';
    return kExitFailed;
  }

  // The console table: the plotted figure as mean ± sd [min, max] (n), the flags as k/n.
  for (const std::string& k : m.keys) out << std::left << std::setw(24) << k << ' ';
  out << std::right << std::setw(8) << "samples";
  if (figure) out << "  " << m.figures[*figure] << ": mean ± sd [min, max] (n)";
  for (std::size_t f = 0; f < m.figures.size(); ++f)
    if (m.kinds[f] == FigureKind::Flag) out << "  " << m.figures[f] << " (true/n)";
  out << '\n';
  for (std::size_t v = 0; v < m.variants.size(); ++v) {
    for (const std::string& value : m.variants[v]) out << std::left << std::setw(24) << value << ' ';
    out << std::right << std::setw(8) << m.rows[v];
    if (figure) {
      const Statistics& st = m.stats[*figure][v];
      if (st.n == 0) out << "  - (0)";
      else
        out << "  " << formatted(st.mean) << " ± " << (st.n > 1 ? formatted(st.sd) : "-") << " ["
            << formatted(st.min) << ", " << formatted(st.max) << "] (" << st.n << ")";
    }
    for (std::size_t f = 0; f < m.figures.size(); ++f)
      if (m.kinds[f] == FigureKind::Flag) out << "  " << m.stats[f][v].true_count << '/' << m.stats[f][v].n;
    out << '\n';
  }
  for (const SampleSet& s : sets)
    if (s.table.not_ok) out << "note: " << s.label << ": " << s.table.not_ok << " run(s) not ok, left out\n";
  out << "wrote " << (o.out_dir / "samples.csv").string() << ", samples.json, samples.md"
      << (figure ? ", samples.png" : " (no figure with numbers: no plot)") << '\n';
  return 0;
}

}  // namespace rocklab::experiments
