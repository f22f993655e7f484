// libFuzzer target: `rocklab render` on a damaged run.h5. Input: patches of the
// values of a good run.h5 (fuzz_support.h). Every frame is read and turned
// into the renderer's frame description (what render draws; the drawing itself
// is left out for speed). A std::exception is the answer render gives to a bad
// file (exit 2); a crash, sanitizer report or hang is a finding.
#include <cstdint>

#include "camera/frame_builder.h"
#include "camera/render_run.h"
#include "fuzz_support.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/sim/output/run_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rocklab;
  const auto file = fuzz::patchedTemplate("run.h5", data, size);
  try {
    sim::output::RunFileReader run(file);
    experiments::Scene scene = experiments::loadSceneText(run.sceneText(), file.string() + ":/scene", {}, {});
    if (!experiments::addRunMaterials(run.materials(), scene.model).empty()) return 0;  // render: exit 2
    const experiments::FrameBuilder builder(scene);
    for (std::size_t k = 0; k < run.frameCount(); ++k) (void)builder.describe(run.frame(k), scene.model, {}, k);
  } catch (const std::exception&) {
  }
  return 0;
}
