#pragma once
// Pixel → world point on a known plane (the chute base, the Perspex wall, the
// plane through the marker centres).
#include <optional>

#include <opencv2/core.hpp>

#include "rocklab/geometry/camera.h"
#include "rocklab/track/link.h"

namespace rocklab::track {

/// Where the ray through `pixel` (Camera::pixelRay: distortion removed) meets the
/// plane through plane_point with normal plane_normal (world frame, any length > 0).
/// Empty when the ray is parallel to the plane, meets it behind the camera, or the
/// pixel lies where the lens distortion cannot be inverted.
std::optional<geometry::Vec3> pixelToPlane(const geometry::Camera& camera, cv::Point2d pixel,
                                           const geometry::Vec3& plane_point, const geometry::Vec3& plane_normal);

/// A track point in the world: its fitted centre when the shape fit gave one
/// (TrackPoint::centre), else its pixel on the plane (pixelToPlane).
std::optional<geometry::Vec3> pointToWorld(const geometry::Camera& camera, const TrackPoint& point,
                                           const geometry::Vec3& plane_point, const geometry::Vec3& plane_normal);

}  // namespace rocklab::track
