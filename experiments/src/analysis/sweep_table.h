#pragma once
// A sweep's sweep.csv read back for analysis (the Weibull fit, strength groups):
// its header and the rows of the runs that ended normally.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rocklab::experiments {

struct SweepTable {
  std::filesystem::path file;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  // status "ok" (or no status column)
  std::size_t not_ok = 0;                      // rows of runs that failed or are missing
  /// Index of a column; throws std::invalid_argument naming the file and the columns.
  std::size_t column(const std::string& name) const;
  /// The cell as a finite number, else nullopt.
  static std::optional<double> numberIn(const std::vector<std::string>& row, std::size_t column);
};

/// Reads a CSV file with a header row (cells quoted as common/csv.h writes them); with a
/// `status` column only the rows whose status is "ok" are kept. Throws
/// std::invalid_argument naming the file (and `missing_hint` when it cannot be read).
SweepTable readCsvTable(const std::filesystem::path& file, const std::string& missing_hint = "");

/// Reads DIR/sweep.csv; throws std::invalid_argument naming the file when it cannot.
SweepTable readSweepTable(const std::filesystem::path& dir);

}  // namespace rocklab::experiments
