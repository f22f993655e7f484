#pragma once
// `rocklab weibull DIR --group-by KEY`: the strength statistics of a crushing
// sweep per value of one varied key (experiments.md §f.5: mean, standard
// deviation and CoV of the strength, porosity and coordination number per r0;
// §e: the size effect sigma_av = a d^b of Eq 5-5 over sizes).
#include <filesystem>
#include <iosfwd>
#include <string>

namespace rocklab::experiments {

struct StrengthGroupOptions {
  std::string strength_column = "strength_MPa";  // MPa
  std::string group_by;                          // a column of sweep.csv (a varied key)
  // Optional: the column giving each run's size d for the size-effect fit over the
  // groups (the mean per group; a column whose name ends in "_m" is in metres and
  // is fitted in mm, as Eq 5-5 is). Empty: no size-effect fit.
  std::string size_column;
};

/// Reads DIR/sweep.csv (rows with status ok), writes DIR/strength_groups.csv (one
/// row per group: its value, runs, mean, standard deviation, CoV, Weibull m,
/// sigma0 and R^2 when it has at least 3 runs, and the mean of every other numeric
/// column), DIR/strength_groups.json and DIR/strength_groups.png (mean strength
/// with its standard deviation against the group value; log-log with the fitted
/// power law when size_column is given). Returns an exit code (2 for a missing
/// file or column).
int strengthGroupsCommand(const std::filesystem::path& dir, const StrengthGroupOptions& options, std::ostream& log);

}  // namespace rocklab::experiments
