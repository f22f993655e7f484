#pragma once
// The force–displacement curves of a crushing batch in one plot (issue 20: a batch
// shows its Weibull plot and its curves): every completed run of a sweep folder
// that wrote runs/NAME/force_displacement.csv, coloured by group.
#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <string>

namespace rocklab::experiments {

/// Writes DIR/force_displacement.png (with its SVG and plotted data beside it): the
/// top platen's force (kN) against its travel (mm) of each run listed in
/// DIR/plan.json whose folder holds a completed results.json and a
/// force_displacement.csv. With `group_by` one of the plan's varied keys, the curves
/// of a group share a colour and one legend entry ("r0 = 2: 20 runs"); otherwise
/// one colour. Returns the number of curves drawn; with none (not a crushing batch,
/// no plan.json) it writes nothing and returns 0. A damaged CSV is skipped with a
/// line in `log` naming it.
std::size_t writeBatchForceCurves(const std::filesystem::path& dir, const std::string& group_by, std::ostream& log);

}  // namespace rocklab::experiments
