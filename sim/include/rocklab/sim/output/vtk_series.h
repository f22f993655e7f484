#pragma once
// ParaView output: one .vtp file per frame (points with radius, velocity, omega,
// force, id as point data; vertex cells) and a .pvd collection that lists them
// with their times. Each file is written to a temporary name and renamed.
#include <filesystem>
#include <string>
#include <vector>

#include "rocklab/sim/snapshot.h"

namespace rocklab::sim::output {

class VtkSeries {
 public:
  /// Files go to `directory/<basename>_NNNNNN.vtp` and `directory/<basename>.pvd`.
  VtkSeries(std::filesystem::path directory, std::string basename);
  void writeFrame(const Snapshot& snapshot);
  /// Rewrites the .pvd with every frame written so far (also called by writeFrame).
  void writeCollection() const;
  std::size_t frameCount() const { return entries_.size(); }

 private:
  std::filesystem::path directory_;
  std::string basename_;
  std::vector<std::pair<double, std::string>> entries_;  // (time s, file name)
};

}  // namespace rocklab::sim::output
