#pragma once
// Linear assignment: rows (tracks) to columns (detections) at least total cost.
#include <vector>

namespace rocklab::track {

/// Optimal assignment by the Hungarian algorithm (Kuhn–Munkres with potentials,
/// O(n² m)). `cost` is row-major, rows × cols, finite. Returns, for each row, its
/// column, or −1 when rows > cols and the row got none. Every row (or every
/// column, if fewer) is assigned: forbid a pair with a large cost and drop it after.
std::vector<int> solveAssignment(const std::vector<double>& cost, int rows, int cols);

/// The greedy baseline, for comparison only: repeatedly take the cheapest pair whose
/// row and column are both free, among pairs with cost ≤ max_cost. Rows left
/// without a column get −1.
std::vector<int> greedyAssignment(const std::vector<double>& cost, int rows, int cols, double max_cost);

}  // namespace rocklab::track
