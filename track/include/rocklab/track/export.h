#pragma once
// Tracks → CSV, one row per point (trackpy / TrackMate style: a `frame` column and
// an `id` particle column), sorted by frame then id:
//   frame,time_s,id,u_px,v_px,x_m,y_m,z_m
// (x, y, z) is the pixel taken to the plane (pixelToPlane, world frame); "nan" when
// its ray misses the plane.
#include <filesystem>
#include <vector>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/vec.h"
#include "rocklab/track/link.h"

namespace rocklab::track {

/// Written to a temporary file beside `path`, then renamed (a reader never sees
/// half a file). Throws std::runtime_error naming the path when it cannot write.
void writeTracksCsv(const std::filesystem::path& path, const std::vector<Track>& tracks,
                    const geometry::Camera& camera, const geometry::Vec3& plane_point,
                    const geometry::Vec3& plane_normal);

}  // namespace rocklab::track
