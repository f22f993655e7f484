#pragma once
// The runs and legend labels of a command that sets finished runs side by side
// (`rocklab products`, `rocklab profiles`): one label a run, in their order, or
// none (the folders' names). Internal.
#include <filesystem>
#include <string>
#include <vector>

namespace rocklab::experiments::detail {

/// "" when there are runs and the labels fit them; else what is wrong (the message
/// after "error: COMMAND: ").
inline std::string runLabelsProblem(std::size_t runs, std::size_t labels) {
  if (runs == 0) return "no run folder given";
  if (labels != 0 && labels != runs)
    return "--label given " + std::to_string(labels) + " times for " + std::to_string(runs) +
           " runs (allowed: one a run, in their order, or none)";
  return {};
}

/// Run k's legend label: its --label, else its folder's name, else its path.
inline std::string runLabel(const std::vector<std::filesystem::path>& runs, const std::vector<std::string>& labels,
                            std::size_t k) {
  const std::string label = labels.empty() ? runs[k].filename().string() : labels[k];
  return label.empty() ? runs[k].string() : label;
}

}  // namespace rocklab::experiments::detail
