#pragma once
// `rocklab render run.h5`: re-renders the frames stored in a run file through the
// scene's cameras or those of a camera file, without running the simulation.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "rocklab/sim/model.h"

namespace rocklab::experiments {

struct RenderRunOptions {
  std::filesystem::path run_file;     // run.h5 (or run.h5.partial of an interrupted run)
  std::filesystem::path camera_file;  // "" = the cameras of the stored scene
  std::filesystem::path out_dir;      // "" = the run file's folder
};

/// Adds to `model` (the stored scene's) the materials the run made, from the
/// file's /materials (sim::output::RunFileReader::materials): the rows past the
/// scene's. "" or why the table does not fit the scene (nothing added then).
std::string addRunMaterials(const std::vector<sim::Material>& stored, sim::Model& model);

/// Renders every stored frame with every camera (movie, stills). Markers are
/// read from results.json beside the run file when it exists. Returns an ExitCode.
int renderRun(const RenderRunOptions& options, std::ostream& log);

}  // namespace rocklab::experiments
