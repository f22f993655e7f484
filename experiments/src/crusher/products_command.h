#pragma once
// `rocklab products RUN_DIR...`: the product curves of finished crusher runs on one
// sieve chart, with a table of their figures (P50, P80, breakages, throughput, the
// passing at every sieve): the comparison of runs that are not one sweep, such as the
// population-balance and the bonded-particle crusher (§g.9, PBM against BPM).
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "common/run_comparison.h"

namespace rocklab::experiments {

/// Exit code: 0, or 2 (a folder without a crusher run's results.json, a damaged curve,
/// runs on different sieves, labels not one a run; nothing written) with the message
/// on err naming the file and key.
int runProductsCommand(const RunComparisonOptions& options, std::ostream& out, std::ostream& err);

}  // namespace rocklab::experiments
