#pragma once
// The inputs of a command that sets finished runs or sets side by side (`rocklab
// products`, `rocklab profiles`, `rocklab samples`): the folders, one legend label a
// folder in their order or none (the folders' names), and the output folder. Internal.
#include <filesystem>
#include <string>
#include <vector>

namespace rocklab::experiments {

struct RunComparisonOptions {
  std::vector<std::filesystem::path> runs;  // the folders compared (finished runs, or sets)
  std::vector<std::string> labels;          // one a folder, or none (the folders' names)
  std::filesystem::path out_dir;            // the command's tables and plots
};

}  // namespace rocklab::experiments

namespace rocklab::experiments::detail {

/// "" when there are folders and the labels fit them; else what is wrong (the message
/// after "error: COMMAND: ").
inline std::string runLabelsProblem(std::size_t runs, std::size_t labels) {
  if (runs == 0) return "no run folder given";
  if (labels != 0 && labels != runs)
    return "--label given " + std::to_string(labels) + " times for " + std::to_string(runs) +
           " folders (allowed: one a folder, in their order, or none)";
  return {};
}

/// Folder k's legend label: its --label, else its folder's name, else its path.
inline std::string runLabel(const std::vector<std::filesystem::path>& runs, const std::vector<std::string>& labels,
                            std::size_t k) {
  const std::string label = labels.empty() ? runs[k].filename().string() : labels[k];
  return label.empty() ? runs[k].string() : label;
}

}  // namespace rocklab::experiments::detail
