// libFuzzer target: `rocklab restart` on a damaged checkpoint. Input: patches
// of the values of a good checkpoint.h5 (fuzz_support.h: dataset elements and
// numeric attributes such as dt and time). The restart path then reads it,
// reads its scene and builds the World; a CheckpointError, SceneError or
// std::invalid_argument is the answer to a bad file. A World that was built
// steps a few times: a crash, sanitizer report or hang there is a finding too.
#include <cstdint>

#include "fuzz_support.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/sim/output/checkpoint.h"
#include "rocklab/sim/world.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rocklab;
  const auto file = fuzz::patchedTemplate("checkpoint.h5", data, size);
  std::unique_ptr<sim::World> world;
  try {
    sim::output::Checkpoint cp = sim::output::readCheckpoint(file);
    const experiments::Scene scene = experiments::loadSceneText(cp.scene_text, file.string() + ":/scene", {}, {});
    world = std::make_unique<sim::World>(scene.model, std::move(cp.state), 1);
  } catch (const sim::output::CheckpointError&) {
    return 0;
  } catch (const experiments::SceneError&) {
    return 0;
  } catch (const std::invalid_argument&) {
    return 0;
  }
  try {
    for (int k = 0; k < 3; ++k) world->step();
  } catch (const sim::WatchdogError&) {  // the run loop stops a blown-up world the same way
  }
  return 0;
}
