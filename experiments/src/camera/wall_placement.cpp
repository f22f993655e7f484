#include "camera/wall_placement.h"

#include <stdexcept>

namespace rocklab::experiments {

using geometry::Vec3;

namespace {

nlohmann::json vec(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

Vec3 vec(const nlohmann::json& j, const char* key) {
  const nlohmann::json& v = j.at(key);
  if (!v.is_array() || v.size() != 3)
    throw std::runtime_error(std::string("wall_placement: ") + key + " is not [x, y, z]");
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

}  // namespace

nlohmann::json wallPlacement(const sim::Model& model) {
  nlohmann::json walls = nlohmann::json::array();
  for (const sim::Wall& w : model.walls) {
    if (w.shape != sim::WallShape::Plane) continue;
    const sim::WallMotion& m = w.motion;
    walls.push_back({{"name", w.name},
                     {"point", vec(w.point)},
                     {"normal", vec(w.normal)},
                     {"motion",
                      {{"velocity", vec(m.velocity)},
                       {"angular_velocity", vec(m.angular_velocity)},
                       {"pivot", vec(m.pivot)},
                       {"amplitude", vec(m.amplitude)},
                       {"frequency", m.frequency}}}});
  }
  return walls;
}

std::size_t applyWallPlacement(const nlohmann::json& placement, sim::Model& model) {
  std::size_t moved = 0;
  try {
    for (const nlohmann::json& p : placement) {
      for (sim::Wall& w : model.walls) {
        if (w.shape != sim::WallShape::Plane || w.name != p.at("name").get<std::string>()) continue;
        const nlohmann::json& m = p.at("motion");
        w.point = vec(p, "point");
        w.normal = vec(p, "normal");
        w.motion.velocity = vec(m, "velocity");
        w.motion.angular_velocity = vec(m, "angular_velocity");
        w.motion.pivot = vec(m, "pivot");
        w.motion.amplitude = vec(m, "amplitude");
        w.motion.frequency = m.at("frequency").get<double>();
        ++moved;
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("wall_placement: ") + e.what());
  }
  return moved;
}

}  // namespace rocklab::experiments
