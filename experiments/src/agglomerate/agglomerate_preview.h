#pragma once
// Preview PNG of an agglomerate: the whole agglomerate (left) and its half behind the
// x-z plane (right, the cut face towards the camera, so the void filling shows),
// spheres coloured by radius from the smallest (blue) to the largest (orange).
#include <filesystem>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::experiments::agglomerate {

/// Renders with OSMesa; throws std::runtime_error when no GL context can be made.
void writeAgglomeratePreview(const std::filesystem::path& png,
                             const std::vector<geometry::Sphere>& spheres);

}  // namespace rocklab::experiments::agglomerate
