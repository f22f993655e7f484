#include "camera/frame_builder.h"

#include "rocklab/sim/wall_motion.h"

namespace rocklab::experiments {

using geometry::Vec3;

FrameBuilder::FrameBuilder(const Scene& scene)
    : looks_(scene.wall_looks), material_colours_(scene.material_colours) {
  for (const sim::Wall& w : scene.model.walls)
    meshes_.push_back(w.shape == sim::WallShape::Mesh ? std::make_shared<const geometry::TriangleMesh>(w.mesh)
                                                      : nullptr);
}

render::FrameDescription FrameBuilder::describe(const sim::Snapshot& s, const sim::Model& model,
                                                const std::unordered_set<std::uint64_t>& marker_bodies,
                                                std::uint64_t index) const {
  render::FrameDescription f;
  f.time = s.time;
  f.index = index;
  f.spheres.reserve(s.position.size());
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    const bool member = !s.clump.empty() && s.clump[i] >= 0;
    const std::uint64_t body = member ? s.clump_id[static_cast<std::size_t>(s.clump[i])] : s.id[i];
    render::SphereInstance sphere;
    sphere.centre = s.position[i];
    sphere.radius = s.radius[i];
    sphere.velocity = s.velocity[i];
    const auto m = static_cast<std::size_t>(s.material[i]);
    sphere.colour = marker_bodies.count(body) ? render::kRedMarker
                    : m < material_colours_.size() ? material_colours_[m]
                                                   : render::kGreyPebble;
    f.spheres.push_back(sphere);
  }
  for (std::size_t k = 0; k < model.walls.size() && k < looks_.size(); ++k) {
    const sim::Wall& w = model.walls[k];
    const WallLook& look = looks_[k];
    const bool active = k < s.wall_active.size() ? s.wall_active[k] != 0 : w.activeAt(s.time);
    if (!look.visible || !active) continue;
    if (w.shape == sim::WallShape::Mesh) {
      render::MeshInstance mesh;
      mesh.mesh = meshes_[k];
      mesh.colour = look.colour;
      mesh.opacity = look.opacity;
      // Rigid motion: rotation about the pivot plus translation (the renderer takes R x + t).
      const sim::WallPose pose = sim::wallPoseAt(w.motion, s.time);
      mesh.rotation = pose.rotation;
      mesh.translation = pose.place(Vec3::Zero());
      f.meshes.push_back(mesh);
      continue;
    }
    render::Polygon poly;
    poly.colour = look.colour;
    poly.opacity = look.opacity;
    const sim::WallPose pose = sim::wallPoseAt(w.motion, s.time);
    if (w.shape == sim::WallShape::Polygon) {
      for (const Vec3& v : w.vertices) poly.vertices.push_back(pose.place(v));
    } else {
      // An infinite plane drawn as a square of plane_size around its point.
      const Vec3 n = w.normal.normalized();
      const Vec3 a = n.unitOrthogonal(), b = n.cross(a);
      const double h = 0.5 * look.plane_size;
      const Vec3 c = pose.place(w.point);
      poly.vertices = {c - h * a - h * b, c + h * a - h * b, c + h * a + h * b, c - h * a + h * b};
    }
    f.polygons.push_back(poly);
  }
  return f;
}

}  // namespace rocklab::experiments
