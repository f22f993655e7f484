// Scene reader: [[cameras]] (also the camera files of `rocklab render`).
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

namespace {

/// The [[cameras]] key behind a geometry::Camera::validate message
/// ("camera.fx must be ..."), so the message blames the key that was written.
std::string sceneKeyOf(const std::string& message) {
  static const std::pair<const char*, const char*> fields[] = {
      {"camera.width", "resolution"}, {"camera.height", "resolution"}, {"camera.fx", "fx"},
      {"camera.fy", "fy"},           {"camera.cx", "cx"},              {"camera.cy", "cy"},
      {"camera.k1", "k1"},           {"camera.k2", "k2"},              {"camera.frameRate", "frame_rate"},
      {"camera.exposureTime", "exposure"}, {"camera.rotation", "up"},  {"camera.translation", "eye"}};
  for (const auto& [field, key] : fields)
    if (message.rfind(std::string(field) + " ", 0) == 0) return key;
  return "exposure";
}

/// [cameras.cut]: the cut-away plane. By default the plane through the camera's
/// target facing the camera across `up` (a vertical plane when up is vertical),
/// removing the half of the scene nearest the camera; with `wedge_normal` a second
/// plane through the same point, and only what lies beyond both goes (a wedge).
render::CutPlane readCut(TableReader& t, const Vec3& eye, const Vec3& target, const Vec3& up) {
  render::CutPlane cut;
  cut.point = t.vec3("point", target);
  const Vec3 u = up.normalized();
  Vec3 towards = eye - cut.point;
  towards -= towards.dot(u) * u;
  const bool facing = towards.norm() > 1e-9 * std::max(1.0, (eye - cut.point).norm());
  if (!t.has("normal") && !facing)
    t.fail("normal", "is needed: the eye lies on the line through point along up, so no plane faces the camera");
  cut.normal = t.vec3("normal", facing ? Vec3(towards.normalized()) : Vec3::UnitX());
  if (!(cut.normal.norm() > 0)) t.fail("normal", "must be non-zero");
  cut.normal.normalize();
  if (t.has("wedge_normal")) {
    Vec3 wedge = t.requiredVec3("wedge_normal");
    if (!(wedge.norm() > 0)) t.fail("wedge_normal", "must be non-zero");
    wedge.normalize();
    // Parallel normals remove a half-space again, opposite ones nothing: a typing slip.
    if (std::abs(wedge.dot(cut.normal)) > 1.0 - 1e-9)
      t.fail("wedge_normal", "must not be parallel to normal (the two planes make a wedge only when they cross)");
    cut.wedge_normal = wedge;
  }
  t.finish();
  return cut;
}

}  // namespace

/// [[cameras]]: intrinsics (fov_deg, or fx/fy/cx/cy), pose (eye, target, up),
/// timing and outputs. Every camera field is checked by
/// geometry::Camera::validate.
void readCameras(TableReader& root, std::vector<CameraSettings>& cameras) {
  for (TableReader t : root.tableArray("cameras")) {
    CameraSettings c;
    c.name = t.string("name", "camera" + std::to_string(cameras.size()));
    if (const std::string problem = folderNameProblem(c.name); !problem.empty()) t.fail("name", problem);
    for (const auto& other : cameras)
      if (other.name == c.name) t.fail("name", "another camera has this name");
    std::vector<double> res = t.numberList("resolution", Range::closed(16, 8192));
    if (res.empty()) res = {640, 480};
    if (res.size() != 2 || res[0] != std::floor(res[0]) || res[1] != std::floor(res[1]))
      t.fail("resolution", "expected [width, height] in whole pixels, 16..8192");
    const int w = static_cast<int>(res[0]), h = static_cast<int>(res[1]);
    geometry::Camera& cam = c.camera;
    if (t.has("fov_deg")) {
      if (t.has("fx")) t.fail("fx", "give fov_deg or fx/fy/cx/cy, not both");
      cam = geometry::Camera::withFieldOfView(w, h,
                                              t.number("fov_deg", 60, {0.0, 179.0, true, false}));
    } else {
      cam.width = w;
      cam.height = h;
      cam.fx = t.requiredNumber("fx", Range::positive());
      cam.fy = t.number("fy", cam.fx, Range::positive());
      cam.cx = t.number("cx", 0.5 * (w - 1));
      cam.cy = t.number("cy", 0.5 * (h - 1));
    }
    cam.k1 = t.number("k1", 0.0);
    cam.k2 = t.number("k2", 0.0);
    cam.frameRate = t.number("frame_rate", 500.0, Range::positive());
    cam.exposureTime = t.number("exposure", 0.0, Range::nonNegative());
    const Vec3 eye = t.requiredVec3("eye"), target = t.requiredVec3("target");
    // lookAt throws for either of two keys: say which.
    if (!((target - eye).norm() > 0)) t.fail("eye", "equals target: the camera must look at a point away from it");
    const Vec3 up = t.vec3("up", Vec3::UnitZ());
    try {
      cam.lookAt(eye, target, up);
    } catch (const std::invalid_argument& e) {
      t.fail("up", e.what());
    }
    try {
      cam.validate();
    } catch (const std::invalid_argument& e) {
      t.fail(sceneKeyOf(e.what()), e.what());
    }
    c.start_time = t.number("start_time", c.start_time, Range::nonNegative());
    c.end_time = t.number("end_time", c.end_time, Range::positive());
    c.movie = t.boolean("movie", c.movie);
    c.movie_fps = t.number("movie_fps", c.movie_fps, Range::closed(1, 1000));
    c.still_interval = t.number("still_interval", c.still_interval, Range::nonNegative());
    c.all_frames = t.boolean("all_frames", c.all_frames);
    c.timestamp = t.boolean("timestamp", c.timestamp);
    c.scale_bar = t.boolean("scale_bar", c.scale_bar);
    c.scale_depth = t.number("scale_depth", (target - eye).norm(), Range::positive());
    c.motion_blur = t.boolean("motion_blur", c.motion_blur);
    c.noise_sigma = t.number("noise_sigma", c.noise_sigma, Range::closed(0, 100));
    c.light_gain = t.number("light_gain", c.light_gain, Range::closed(0, 10));
    c.ambient = t.number("ambient", c.ambient, Range::closed(0, 2));
    c.diffuse = t.number("diffuse", c.diffuse, Range::closed(0, 2));
    c.specular = t.number("specular", c.specular, Range::closed(0, 2));
    c.colour_by = t.choice("colour_by", c.colour_by, {{ColourBy::Material, "material"}, {ColourBy::Fragment, "fragment"}});
    if (c.motion_blur && !(cam.exposureTime > 0)) t.fail("motion_blur", "needs exposure > 0 s");
    if (auto cut = t.table("cut")) c.cut = readCut(*cut, eye, target, up);
    t.finish();
    cameras.push_back(c);
  }
}

}  // namespace rocklab::experiments::detail
