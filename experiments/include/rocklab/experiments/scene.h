#pragma once
// Scenes are TOML files (assets/scenes/*.toml). Loading one validates every
// key: an unknown key, a wrong type or a value out of range is a SceneError
// whose message names the file, line, key, value and what is allowed.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "rocklab/sim/model.h"

namespace rocklab::experiments {

struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// How a run is driven and what it writes.
struct RunSettings {
  std::string name;
  std::string description;
  std::uint64_t seed = 1;
  double end_time = 0.0;       // s; or...
  std::uint64_t steps = 0;     // ...a step count (exactly one of the two is set)
  double frame_interval = 0.0;       // s between trajectory frames; 0 = first and last only
  double energy_interval = 0.0;      // s between energy-log rows; 0 = at frames only
  double checkpoint_interval = 0.0;  // s between checkpoints; 0 = at the end only
  bool hdf5 = true;            // run.h5
  bool vtk = false;            // .vtp/.pvd series
  bool checkpoint = true;      // checkpoint.h5
};

struct Scene {
  std::filesystem::path source;  // file it came from ("" for text)
  std::string text;              // effective TOML (overrides applied), stored with outputs
  sim::Model model;
  std::vector<sim::SphereSpec> spheres;
  RunSettings run;
};

/// Parses and validates a scene. `overrides` are "key.path=value" strings
/// (from --set), applied before validation; value is TOML (1e-6, "text", [0,0,1]).
Scene loadScene(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});
Scene loadSceneText(const std::string& text, const std::string& source_name,
                    const std::vector<std::string>& overrides = {},
                    const std::filesystem::path& base_dir = {});

/// Directory of the built-in scenes, and the resolution of a bare name ("pour")
/// to a file in it.
std::filesystem::path builtinSceneDir();
std::filesystem::path resolveScene(const std::string& name_or_path);

}  // namespace rocklab::experiments
