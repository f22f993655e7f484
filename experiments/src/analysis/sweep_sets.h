#pragma once
// Finished sweeps read back as sets for the commands that put several side by side
// (`rocklab samples`: samples of the same variants merged; `rocklab sweeps`: one
// series a sweep). Internal.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "analysis/sweep_table.h"

namespace rocklab::experiments::detail {

/// A folder that is not a finished sweep, or sweeps that cannot go together; the
/// message names the file, key and what is allowed.
struct SweepSetError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// One finished sweep: its varied keys and table (its runs that ended normally).
struct SweepSet {
  std::string label;
  std::filesystem::path dir;
  std::vector<std::string> keys;  // the plan's order
  std::string x_over;             // the sweep's --x-over ("" none): its plot's x is the first key over it
  SweepTable table;
};

/// Reads DIR/plan.json (a sweep's) and DIR/sweep.csv; throws SweepSetError.
SweepSet readSweepSet(const std::filesystem::path& dir);

/// The columns of a set's table that are figures: neither a varied key nor the status.
std::vector<std::string> figureColumns(const SweepSet& s);

/// Names sorted and joined for a message ("none" when empty).
std::string sortedNames(std::vector<std::string> names);

/// The sets must vary the same keys, tabulate the same figures (in any order) and be
/// plotted against the same x (`what_allowed` says what the command takes, e.g. "one a
/// sample"); throws SweepSetError naming both files.
void checkSameShape(const std::vector<SweepSet>& sets, const std::string& what_allowed);

}  // namespace rocklab::experiments::detail
