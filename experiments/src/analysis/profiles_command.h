#pragma once
// `rocklab profiles RUN_DIR...`: the marker velocity profiles and discharge curves of
// finished chute runs side by side: one plot a marker column (velocity against the
// marker's starting height, a series a run), the discharged mass against time after
// the gate, and a table of each run's clearance and column means. The comparison of
// runs that are not one sweep: the zoned chute's two deposition methods (§d), a case
// across its samples, or the lab cases of one sample.
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "common/run_comparison.h"

namespace rocklab::experiments {

/// Exit code: 0, or 2 (a folder without a chute run's results.json, a marker without
/// its figures, labels not one a run; nothing written) with the message on err naming
/// the file and key.
int runProfilesCommand(const RunComparisonOptions& options, std::ostream& out, std::ostream& err);

}  // namespace rocklab::experiments
