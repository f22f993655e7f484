#pragma once
// CSV cells as every table rocklab writes them (sweep.csv, products.csv, a plot's
// data) and reads them back (sweep tables, report pages): a cell holding a comma, a
// quote or a line break is quoted, its quotes doubled (RFC 4180); a vary value such
// as [0,0,0.05] or an error message stays one cell. Internal.
#include <string>
#include <vector>

namespace rocklab::experiments::detail {

inline std::string csvCell(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

/// One line of cells as csvCell writes them; a trailing comma gives an empty last cell.
inline std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c != '"')
        cells.back() += c;
      else if (i + 1 < line.size() && line[i + 1] == '"')
        cells.back() += line[++i];  // a doubled quote inside a quoted cell
      else
        quoted = false;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.emplace_back();
    } else {
      cells.back() += c;
    }
  }
  return cells;
}

}  // namespace rocklab::experiments::detail
