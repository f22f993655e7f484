#pragma once
// ParaView output: one .vtp file per frame and a .pvd collection that lists them
// with their times. Each file is written to a temporary name and renamed. A
// series holds either the balls (points with radius, velocity, omega, force, id
// as point data; vertex cells) or the walls (triangles where each wall is at the
// frame's time: moving walls at their pose), so ParaView shows both side by side.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "rocklab/sim/model.h"
#include "rocklab/sim/snapshot.h"

namespace rocklab::sim::output {

class VtkSeries {
 public:
  /// Files go to `directory/<basename>_NNNNNN.vtp` and `directory/<basename>.pvd`.
  VtkSeries(std::filesystem::path directory, std::string basename);
  void writeFrame(const Snapshot& snapshot);
  /// The mesh and polygon walls active at `time`, placed by their motion
  /// (wall_motion.h): triangles with cell data `wall` (index in model.walls) and
  /// point data `velocity` (the wall material's, spin included). Infinite planes
  /// are not drawn (they have no extent).
  void writeWalls(const Model& model, double time);
  /// Rewrites the .pvd with every frame written so far (also called by writeFrame).
  void writeCollection() const;
  std::size_t frameCount() const { return entries_.size(); }

 private:
  std::filesystem::path directory_;
  std::string basename_;
  std::vector<std::pair<double, std::string>> entries_;  // (time s, file name)
  void addFrame(double time, const std::function<void(const std::filesystem::path&)>& write);
};

}  // namespace rocklab::sim::output
