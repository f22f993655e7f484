#pragma once
// `rocklab contrast A B`: two sets of samples (folders written by `rocklab samples`)
// compared variant by variant: for every figure with numbers in both, the ratio of
// their means (A / B) or their difference (A - B), with its scatter from both sample
// standard deviations (ratio: relative scatters in quadrature; difference: absolute
// ones). What the studies asked for and had been divided by hand: the sphere/clump
// velocity ratio per column of the single-size chute over its seeds, the per-zone
// velocity difference between the zoned chute's two deposition methods.
//
// Variants are matched on the keys both sets vary; a key only one set varies (the CSS
// of the laboratory cases, beside a set at one CSS) is fixed with `where` (key=value,
// as its samples.json writes the value). Writes contrast.csv, contrast.json and
// contrast.md (a cell "value ± scatter (n_A, n_B)").
#include <ostream>
#include <string>
#include <vector>

#include "common/run_comparison.h"

namespace rocklab::experiments {

enum class ContrastOp { Ratio, Difference };

struct ContrastOptions {
  RunComparisonOptions sets;        // exactly two folders: A then B
  ContrastOp op = ContrastOp::Ratio;
  std::vector<std::string> where;   // key=value: only the variants with that value (in the set that varies key)
};

/// Exit code 0, or 2 (not two folders, a folder without samples.json, no varied key in
/// common, a `where` not key=value or naming a key neither set varies or a value none
/// of its variants has, two variants of one set alike on the common keys; nothing
/// written) with the message on err naming the file, key and what is allowed.
int runContrastCommand(const ContrastOptions& options, std::ostream& out, std::ostream& err);

}  // namespace rocklab::experiments
