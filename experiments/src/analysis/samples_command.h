#pragma once
// `rocklab samples SWEEP_DIR...`: sweeps of the same variants on different samples
// merged into each variant's mean and scatter. A sample is what the sweeps' runs do
// not vary but the result depends on: the random packing of a seed, or the deposit a
// set of chute cases restarts from (`rocklab sweep DEPOSIT/checkpoint.h5 ...`: one
// deposit a sample, so the cases of one sample share its bed and the samples are
// separate sweeps), or with `over` a key the sweeps vary (scene.seed): each of its
// values in each sweep is a sample, the variants the combinations of the other keys.
//
// Writes samples.csv (a row a variant: its varied values, then for each figure of the
// sweeps' tables its mean, sample standard deviation, minimum, maximum and count over
// the samples that have it; true/false figures as the count of true), samples.json (the
// same with each sample's value) and samples.png (one figure against the first varied
// key with numbers: each sample a point, the mean a line where every sample has one).
#include <ostream>
#include <string>

#include "common/run_comparison.h"

namespace rocklab::experiments {

/// `figure`: the column to plot and print ("" = the first with numbers); `over`: a
/// varied key whose values are samples ("" = none: a sample a folder). Exit code 0, or 2
/// (a folder without a finished sweep, sweeps that vary different keys or tabulate
/// different figures, a figure or `over` key not in them, labels not one a folder;
/// nothing written) with the message on err naming the file, key and what is allowed.
int runSamplesCommand(const RunComparisonOptions& options, const std::string& figure, const std::string& over,
                      std::ostream& out, std::ostream& err);

}  // namespace rocklab::experiments
