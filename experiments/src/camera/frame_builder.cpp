#include "camera/frame_builder.h"

#include <algorithm>

#include "camera/fragment_colours.h"
#include "camera/plane_look.h"
#include "rocklab/sim/wall_motion.h"

namespace rocklab::experiments {

using geometry::Vec3;

std::string sceneIndexProblem(const sim::Snapshot& s, const sim::Model& model) {
  const std::size_t materials = model.materials.size();
  for (std::size_t i = 0; i < s.material.size(); ++i)
    if (s.material[i] < 0 || static_cast<std::size_t>(s.material[i]) >= materials)
      return "material row " + std::to_string(i) + ": " + std::to_string(s.material[i]) + " (allowed: 0 to " +
             std::to_string(materials - 1) + ", the scene has " + std::to_string(materials) + " materials)";
  if (s.wall_active.size() > model.walls.size())
    return "wall_active row " + std::to_string(model.walls.size()) + ": the frame has " +
           std::to_string(s.wall_active.size()) + " walls (allowed: at most the scene's " +
           std::to_string(model.walls.size()) + ")";
  return {};
}

FrameBuilder::FrameBuilder(const Scene& scene, ColourBy colour_by)
    : looks_(scene.wall_looks), material_colours_(scene.material_colours), colour_by_(colour_by) {
  for (std::size_t k = 0; k < scene.model.walls.size(); ++k) {
    const sim::Wall& w = scene.model.walls[k];
    const bool slab = w.shape == sim::WallShape::Plane && k < looks_.size() && looks_[k].plane_thickness > 0;
    meshes_.push_back(w.shape == sim::WallShape::Mesh ? std::make_shared<const geometry::TriangleMesh>(w.mesh)
                      : slab                          ? std::make_shared<const geometry::TriangleMesh>(planeSlab(looks_[k]))
                                                      : nullptr);
  }
}

render::FrameDescription FrameBuilder::describe(const sim::Snapshot& s, const sim::Model& model,
                                                const std::unordered_set<std::uint64_t>& marker_bodies,
                                                std::uint64_t index) const {
  render::FrameDescription f;
  f.time = s.time;
  f.index = index;
  // A material made during the run (a breakage's fragment class) in the colour
  // of the one it was made from (Material::made_from, an earlier row).
  std::vector<render::Rgb> by_material(std::max(model.materials.size(), material_colours_.size()),
                                       render::kGreyPebble);
  for (std::size_t m = 0; m < by_material.size(); ++m) {
    const int from = m < model.materials.size() ? model.materials[m].made_from : -1;
    by_material[m] = m < material_colours_.size()                      ? material_colours_[m]
                     : from >= 0 && static_cast<std::size_t>(from) < m ? by_material[static_cast<std::size_t>(from)]
                                                                       : render::kGreyPebble;
  }
  const std::size_t n = s.position.size();
  std::vector<render::Rgb> colour(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto m = static_cast<std::size_t>(s.material[i]);
    colour[i] = m < by_material.size() ? by_material[m] : render::kGreyPebble;
  }
  if (colour_by_ == ColourBy::Fragment) colour = fragmentColours(s, colour);
  f.spheres.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool member = !s.clump.empty() && s.clump[i] >= 0;
    const std::uint64_t body = member ? s.clump_id[static_cast<std::size_t>(s.clump[i])] : s.id[i];
    render::SphereInstance sphere;
    sphere.centre = s.position[i];
    sphere.radius = s.radius[i];
    sphere.velocity = s.velocity[i];
    sphere.colour = marker_bodies.count(body) ? render::kRedMarker : colour[i];
    f.spheres.push_back(sphere);
  }
  for (std::size_t k = 0; k < model.walls.size() && k < looks_.size(); ++k) {
    const sim::Wall& w = model.walls[k];
    const WallLook& look = looks_[k];
    const bool active = k < s.wall_active.size() ? s.wall_active[k] != 0 : w.activeAt(s.time);
    if (!look.visible || !active) continue;
    const sim::WallPose pose = sim::wallPoseAt(w.motion, s.time);
    if (meshes_[k]) {
      render::MeshInstance mesh;
      mesh.mesh = meshes_[k];
      mesh.colour = look.colour;
      mesh.opacity = look.opacity;
      // Rigid motion: the renderer takes R x + t. A mesh wall is in world
      // coordinates, a plane's slab in the plane's frame at its point.
      const bool plane = w.shape == sim::WallShape::Plane;
      mesh.rotation = plane ? geometry::Mat3(pose.rotation * planeFrame(w.normal)) : pose.rotation;
      mesh.translation = pose.place(plane ? w.point : Vec3::Zero());
      f.meshes.push_back(mesh);
      continue;
    }
    render::Polygon poly;
    poly.colour = look.colour;
    poly.opacity = look.opacity;
    if (w.shape == sim::WallShape::Polygon) {
      for (const Vec3& v : w.vertices) poly.vertices.push_back(pose.place(v));
    } else {
      // An infinite plane: its outline (a square or a disc) around its point.
      const geometry::Mat3 frame = planeFrame(w.normal);
      for (const Vec3& v : planeOutline(look)) poly.vertices.push_back(pose.place(w.point + frame * v));
    }
    f.polygons.push_back(poly);
  }
  return f;
}

}  // namespace rocklab::experiments
