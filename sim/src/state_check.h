#pragma once
// The value check of a saved state (WorldState) before a World restarts from it:
// a checkpoint is input like a scene, and an index out of range or a zero radius
// would read past a table or hang the neighbour search. Internal to rocklab_sim.
#include <string>

#include "rocklab/sim/model.h"
#include "rocklab/sim/world.h"

namespace rocklab::sim::detail {

/// "" or what makes the arrays of `state` unusable together: sizes that disagree.
/// The checkpoint writer and reader use it alone: they carry any values.
std::string stateShapeProblem(const WorldState& state);

/// "" or the first value of `state` that a World of `model` cannot run from, as
/// "<dataset> row <k>: <value> (allowed: <what>)", the dataset named as the
/// checkpoint stores it (particles/radius, clumps/orientation, pairs/i, bonds/kind,
/// or the attribute dt, time, step). Checks the sizes first, then every value.
std::string stateProblem(const Model& model, const WorldState& state);

}  // namespace rocklab::sim::detail
