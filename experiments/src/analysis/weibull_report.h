#pragma once
// `rocklab weibull DIR`: the Weibull analysis (weibull.h) of a batch of
// crushing runs, from the strength column of its sweep.csv.
#include <filesystem>
#include <iosfwd>
#include <string>

namespace rocklab::experiments {

/// Reads DIR/sweep.csv (the rows whose status is ok), fits `column` (a strength
/// in MPa, e.g. strength_MPa) and writes DIR/weibull.json and the Weibull plot
/// DIR/weibull.png. Returns the exit code (2 for a missing file or column, or
/// fewer than three strengths).
int weibullCommand(const std::filesystem::path& dir, const std::string& column, std::ostream& log);

}  // namespace rocklab::experiments
