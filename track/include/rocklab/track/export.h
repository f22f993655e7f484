#pragma once
// Tracks → CSV, one row per point (trackpy / TrackMate style: a `frame` column and
// an `id` particle column), sorted by frame then id:
//   frame,time_s,id,u_px,v_px,x_m,y_m,z_m
// (x, y, z) is the pixel taken to the plane (pixelToPlane, world frame); "nan" when
// its ray misses the plane.
//
// Tracked beside truth (evaluate.h), one row per truth-track pair of a frame:
//   frame,marker,track_id,truth_u_px,truth_v_px,tracked_u_px,tracked_v_px,
//   truth_x_m,truth_y_m,truth_z_m,tracked_x_m,tracked_y_m,tracked_z_m
#include <filesystem>
#include <vector>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/vec.h"
#include "rocklab/track/evaluate.h"
#include "rocklab/track/link.h"

namespace rocklab::track {

/// Written to a temporary file beside `path`, then renamed (a reader never sees
/// half a file). Throws std::runtime_error naming the path when it cannot write.
void writeTracksCsv(const std::filesystem::path& path, const std::vector<Track>& tracks,
                    const geometry::Camera& camera, const geometry::Vec3& plane_point,
                    const geometry::Vec3& plane_normal);

/// The evaluation's pairs (`marker` is the truth's id), written the same way.
void writePairedCsv(const std::filesystem::path& path, const TrackingEvaluation& evaluation,
                    const std::vector<TruthMarker>& truth);

}  // namespace rocklab::track
