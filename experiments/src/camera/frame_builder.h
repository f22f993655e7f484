#pragma once
// A simulation snapshot as the renderer's frame description: every ball a
// sphere (marker bodies red, the others in their material's colour), every
// active wall a polygon, a square (infinite planes) or a mesh, in its pose at
// the snapshot's time. The renderer never sees sim types.
#include <cstdint>
#include <memory>
#include <unordered_set>
#include <vector>

#include "rocklab/experiments/scene.h"
#include "rocklab/render/frame.h"
#include "rocklab/sim/snapshot.h"

namespace rocklab::experiments {

class FrameBuilder {
 public:
  explicit FrameBuilder(const Scene& scene);
  /// `model` is the world's current model (walls may have been switched on or off).
  render::FrameDescription describe(const sim::Snapshot& s, const sim::Model& model,
                                    const std::unordered_set<std::uint64_t>& marker_bodies,
                                    std::uint64_t index) const;

 private:
  std::vector<WallLook> looks_;
  std::vector<render::Rgb> material_colours_;
  std::vector<std::shared_ptr<const geometry::TriangleMesh>> meshes_;  // per wall (mesh walls only)
};

}  // namespace rocklab::experiments
