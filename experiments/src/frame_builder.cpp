#include "frame_builder.h"

#include <cmath>
#include <numbers>

namespace rocklab::experiments {

using geometry::Vec3;

geometry::Vec3 wallPointAt(const sim::WallMotion& m, const Vec3& x0, double t) {
  // x(t) = pivot + T(t) + R(t) (x0 - pivot), as in sim/src/wall_runtime.h.
  const Vec3 translation = m.velocity * t + m.amplitude * std::sin(2.0 * std::numbers::pi * m.frequency * t);
  const double angle = m.angular_velocity.norm() * t;
  const Vec3 arm = x0 - m.pivot;
  const Vec3 turned = angle > 0 ? Vec3(Eigen::AngleAxisd(angle, m.angular_velocity.normalized()) * arm) : arm;
  return m.pivot + translation + turned;
}

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
      const Vec3 origin = wallPointAt(w.motion, Vec3::Zero(), s.time);
      const double angle = w.motion.angular_velocity.norm() * s.time;
      if (angle > 0) mesh.rotation = Eigen::AngleAxisd(angle, w.motion.angular_velocity.normalized()).toRotationMatrix();
      mesh.translation = origin;
      f.meshes.push_back(mesh);
      continue;
    }
    render::Polygon poly;
    poly.colour = look.colour;
    poly.opacity = look.opacity;
    if (w.shape == sim::WallShape::Polygon) {
      for (const Vec3& v : w.vertices) poly.vertices.push_back(wallPointAt(w.motion, v, s.time));
    } else {
      // An infinite plane drawn as a square of plane_size around its point.
      const Vec3 n = w.normal.normalized();
      const Vec3 a = n.unitOrthogonal(), b = n.cross(a);
      const double h = 0.5 * look.plane_size;
      const Vec3 c = wallPointAt(w.motion, w.point, s.time);
      poly.vertices = {c - h * a - h * b, c + h * a - h * b, c + h * a + h * b, c - h * a + h * b};
    }
    f.polygons.push_back(poly);
  }
  return f;
}

}  // namespace rocklab::experiments
