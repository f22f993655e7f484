#pragma once
// Where the plane walls of a run were at its end: an experiment may place
// walls when it switches phase (the Zwick platens go where the specimen is),
// which the stored scene does not know. The run writes them to results.json
// ("wall_placement"); `rocklab render` draws the stored frames with them.
#include <nlohmann/json.hpp>

#include "rocklab/sim/model.h"

namespace rocklab::experiments {

/// [{name, point m, normal, motion: {velocity m/s, angular_velocity rad/s,
/// pivot m, amplitude m, frequency Hz}}] for every plane wall of `model`.
nlohmann::json wallPlacement(const sim::Model& model);

/// Puts each plane wall of `model` named in `placement` where it says; walls
/// not named, or not planes, stay as they are. Returns how many it moved.
/// Throws std::runtime_error on a malformed entry.
std::size_t applyWallPlacement(const nlohmann::json& placement, sim::Model& model);

}  // namespace rocklab::experiments
