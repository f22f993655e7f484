#include "camera/render_run.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <unordered_set>

#include "camera/camera_recorder.h"
#include "camera/wall_placement.h"
#include "rocklab/experiments/run.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/sim/output/run_file.h"

namespace rocklab::experiments {

std::string addRunMaterials(const std::vector<sim::Material>& stored, sim::Model& model) {
  if (stored.empty()) return {};
  const std::size_t own = model.materials.size();
  if (stored.size() < own)
    return "/materials has " + std::to_string(stored.size()) + " rows, fewer than the stored scene's " +
           std::to_string(own) + " materials";
  for (std::size_t k = 0; k < own; ++k)
    if (stored[k].name != model.materials[k].name)
      return "/materials row " + std::to_string(k) + " is '" + stored[k].name + "', the stored scene's material " +
             std::to_string(k) + " is '" + model.materials[k].name + "'";
  model.materials.insert(model.materials.end(), stored.begin() + static_cast<std::ptrdiff_t>(own), stored.end());
  return {};
}

int renderRun(const RenderRunOptions& o, std::ostream& log) {
  try {
    sim::output::RunFileReader run(o.run_file);
    Scene scene = loadSceneText(run.sceneText(), o.run_file.string() + ":/scene", {}, o.run_file.parent_path());
    if (const std::string bad = addRunMaterials(run.materials(), scene.model); !bad.empty()) {
      log << "error: run file '" << o.run_file.string() << "': " << bad << "\n";
      return kExitBadInput;
    }
    std::vector<CameraSettings> cameras = o.camera_file.empty() ? scene.cameras : loadCameras(o.camera_file);
    if (cameras.empty()) {
      log << "error: " << o.run_file.string() << ": the stored scene has no [[cameras]]; give --camera CAMERA.toml\n";
      return kExitBadInput;
    }
    if (run.frameCount() == 0) {
      log << "error: " << o.run_file.string() << ": no frames stored (set output.frame_interval when running)\n";
      return kExitBadInput;
    }
    // The whole file is read and checked before anything is written: a damaged
    // frame must not leave some stills replaced and the rest old.
    for (std::size_t k = 0; k < run.frameCount(); ++k)
      if (const std::string bad = sceneIndexProblem(run.frame(k), scene.model); !bad.empty()) {
        log << "error: run file '" << o.run_file.string() << "' frame " << k << ": " << bad;
        if (run.materials().empty() && bad.starts_with("material"))
          log << "; the file has no /materials, the table of the materials made during the run (a breakage's "
                 "fragment classes): it was written before rocklab stored them (2026-12-05). Run the scene "
                 "again to re-render it";
        log << "\n";
        return kExitBadInput;
      }
    // From results.json beside the run: the markers the chute chose, and where
    // the experiment placed the plane walls (the Zwick platens; its last placement).
    std::unordered_set<std::uint64_t> markers;
    const std::filesystem::path results_path = o.run_file.parent_path() / "results.json";
    std::ifstream results(results_path);
    if (results) {
      try {
        const nlohmann::json r = nlohmann::json::parse(results, nullptr, false);
        if (r.is_object() && r.contains("markers"))
          for (const auto& m : r["markers"]) markers.insert(m.at("id").get<std::uint64_t>());
        if (r.is_object() && r.contains("wall_placement")) applyWallPlacement(r["wall_placement"], scene.model);
      } catch (const std::exception& e) {  // a hand-edited or damaged results.json
        log << "error: " << results_path.string() << ": " << e.what() << "\n";
        return kExitBadInput;
      }
    }
    const std::filesystem::path out = o.out_dir.empty() ? o.run_file.parent_path() : o.out_dir;
    std::filesystem::create_directories(out);
    // Every stored frame within each camera's start_time..end_time (its frame_rate
    // does not thin them: the stored frames are what there is).
    std::vector<std::unique_ptr<CameraRecorder>> recorders;
    for (const CameraSettings& c : cameras) recorders.push_back(std::make_unique<CameraRecorder>(c, scene, out, log));
    for (std::size_t k = 0; k < run.frameCount(); ++k) {
      const sim::Snapshot& s = run.frame(k);
      for (auto& r : recorders)
        if (r->inWindow(s.time)) r->record(s, scene.model, markers);
    }
    nlohmann::json list = nlohmann::json::array();
    for (auto& r : recorders) r->finish(list);
    for (const auto& c : list)
      log << "render: camera '" << c["name"].get<std::string>() << "': " << c["frames"] << " frames in "
          << c["render_s"].get<double>() << " s" << (c.contains("movie") ? ", movie " + c["movie"].get<std::string>() : "")
          << " in " << out.string() << "\n";
    return kExitOk;
  } catch (const SceneError& e) {
    log << "error: " << e.what() << "\n";
  } catch (const std::exception& e) {
    log << "error: " << e.what() << "\n";
  }
  return kExitBadInput;
}

}  // namespace rocklab::experiments
