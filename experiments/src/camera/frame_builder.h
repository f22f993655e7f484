#pragma once
// A simulation snapshot as the renderer's frame description: every ball a
// sphere (marker bodies red, the others in their material's colour, a material
// made during the run in that of the one it was made from (Material::made_from),
// or by fragment: camera/fragment_colours.h), every active wall a polygon, a mesh,
// or for an infinite plane its look (camera/plane_look.h: square or disc, flat
// or a slab), in its pose at the snapshot's time. The renderer never sees sim types.
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_set>
#include <vector>

#include "rocklab/experiments/scene.h"
#include "rocklab/render/frame.h"
#include "rocklab/sim/snapshot.h"

namespace rocklab::experiments {

/// "" or the first index of a snapshot read back from a file that `model`'s
/// tables do not have, as "<array> row <k>: <value> (allowed: ...)": a material
/// past the scene's materials, a wall_active longer than its walls. (The file
/// reader checks the rest: sim::output::RunFileReader::frame.)
std::string sceneIndexProblem(const sim::Snapshot& s, const sim::Model& model);

class FrameBuilder {
 public:
  explicit FrameBuilder(const Scene& scene, ColourBy colour_by = ColourBy::Material);
  /// `model` is the world's current model (walls may have been switched on or off,
  /// materials added: a breakage's fragment classes).
  render::FrameDescription describe(const sim::Snapshot& s, const sim::Model& model,
                                    const std::unordered_set<std::uint64_t>& marker_bodies,
                                    std::uint64_t index) const;

 private:
  std::vector<WallLook> looks_;
  std::vector<render::Rgb> material_colours_;
  ColourBy colour_by_;
  // Per wall: the mesh of a mesh wall, or the slab of a plane drawn with
  // thickness (in the plane's frame); null for the others.
  std::vector<std::shared_ptr<const geometry::TriangleMesh>> meshes_;
};

}  // namespace rocklab::experiments
