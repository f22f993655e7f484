#include "analysis/sweep_table.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/csv.h"

namespace rocklab::experiments {

using detail::splitCsvLine;

std::size_t SweepTable::column(const std::string& name) const {
  for (std::size_t k = 0; k < header.size(); ++k)
    if (header[k] == name) return k;
  std::string names;
  for (const std::string& h : header) names += (names.empty() ? "" : ", ") + h;
  throw std::invalid_argument(file.string() + ": no column '" + name + "' (columns: " + names +
                              "); sweep with --metric " + name);
}

std::optional<double> SweepTable::numberIn(const std::vector<std::string>& row, std::size_t column) {
  if (column >= row.size() || row[column].empty()) return std::nullopt;
  try {
    std::size_t used = 0;
    const double v = std::stod(row[column], &used);
    if (used == row[column].size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

SweepTable readCsvTable(const std::filesystem::path& file, const std::string& missing_hint) {
  SweepTable t;
  t.file = file;
  std::ifstream in(t.file);
  if (!in) throw std::invalid_argument(t.file.string() + ": cannot read" + missing_hint);
  std::string line;
  if (!std::getline(in, line)) throw std::invalid_argument(t.file.string() + ": empty (no header)");
  t.header = splitCsvLine(line);
  std::size_t status = t.header.size();
  for (std::size_t k = 0; k < t.header.size(); ++k)
    if (t.header[k] == "status") status = k;
  while (std::getline(in, line)) {
    std::vector<std::string> cells = splitCsvLine(line);
    if (status < t.header.size() && (status >= cells.size() || cells[status] != "ok"))
      ++t.not_ok;
    else
      t.rows.push_back(std::move(cells));
  }
  return t;
}

SweepTable readSweepTable(const std::filesystem::path& dir) {
  return readCsvTable(dir / "sweep.csv", " (run a sweep over the batch first, e.g. --vary scene.seed=1,2,...)");
}

}  // namespace rocklab::experiments
