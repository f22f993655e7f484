#pragma once
// `rocklab sweeps SWEEP_DIR...`: finished sweeps of the same keys side by side, a
// series each, where they are not samples of one another but differ in what their
// runs start from: the zoned chute's single-size CSS sweep, one deposit (and so one
// sweep) a clump size, plotted together against CSS / d_eq (experiments.md §d).
//
// Writes sweeps.csv (every sweep's rows, a `sweep` column first with its label, then
// the first sweep's columns, and with --x-over the plotted x as a column), sweeps.json
// (the same by sweep) and sweeps.png (one figure against the first varied key, or its
// value over each row's own --x-over figure: a series a sweep, a line broken where a
// run has no value, e.g. a jammed case's clearance time).
#include <ostream>
#include <string>

#include "common/run_comparison.h"

namespace rocklab::experiments {

/// `figure`: the column to plot ("" = the first figure with numbers). Exit code 0, or 2
/// (a folder without a finished sweep, sweeps that vary different keys or tabulate
/// different figures, a figure not in them, labels not one a folder; nothing written)
/// with the message on err naming the file, key and what is allowed.
int runSweepsCommand(const RunComparisonOptions& options, const std::string& figure, std::ostream& out,
                     std::ostream& err);

}  // namespace rocklab::experiments
