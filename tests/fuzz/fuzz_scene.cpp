// libFuzzer target: the scene reader with --set overrides. Input: the scene
// text, then NUL-separated --set assignments. A SceneError is the answer to a
// bad scene; any other exception, a crash, a sanitizer report or a hang is a
// finding. A scene the reader accepts is also built into a World (whose own
// checks may refuse it with std::invalid_argument, as `rocklab run` reports).
#include <cstdint>

#include "fuzz_support.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/sim/world.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rocklab;
  std::vector<std::string> parts = fuzz::splitInput(data, size, 9);
  const std::string text = parts.front();
  parts.erase(parts.begin());
  experiments::Scene scene;
  try {
    // Files a scene names are looked up in an empty folder.
    scene = experiments::loadSceneText(text, "fuzz.toml", parts, fuzz::scratchDir());
  } catch (const experiments::SceneError&) {
    return 0;
  }
  // Small worlds only: the time goes into the readers, not into packing.
  if (scene.spheres.size() + scene.clumps.size() > 2000) return 0;
  try {
    sim::World world(scene.model, scene.spheres, scene.clumps, scene.bonds, 1);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
