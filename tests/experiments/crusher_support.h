#pragma once
// The tiny crusher run of the CI tests: the PBM scene with six 8-9 mm spheres
// (finer than the 11.6 mm closed-side gap), soft contacts (1e7 N/m: a coarse step)
// and the stop wall gone at 0.02 s.
#include <string>
#include <vector>

namespace rocklab::experiments::test {

/// `scene_file`: a scene of assets/scenes/ that extends cone-crusher-pbm.toml.
inline std::vector<std::string> tinyCrusherRunArgs(const std::string& out, int threads = 1,
                                                   const std::string& scene_file = "cone-crusher-pbm.toml") {
  const std::string scene = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/" + scene_file;
  std::vector<std::string> args{"run", scene, "--out", out, "--threads", std::to_string(threads), "--quiet",
                                "--set", "crusher.release_time=0.02", "--set", "scene.end_time=2.0",
                                "--set", "output.frame_interval=0.05"};
  for (const char* m : {"rock_small", "rock_medium", "rock_large"})
    for (const char* k : {"kn", "ks"}) args.insert(args.end(), {"--set", std::string("materials.") + m + "." + k + "=1e7"});
  for (int s = 0; s < 3; ++s) {
    const std::string p = "particles." + std::to_string(s) + ".";
    const double z = 0.165 + 0.035 * s;
    args.insert(args.end(), {"--set", p + "count=2", "--set", p + "radius_min=0.004", "--set", p + "radius_max=0.0045",
                             "--set", p + "region_min=[-0.045,-0.045," + std::to_string(z) + "]",
                             "--set", p + "region_max=[0.045,0.045," + std::to_string(z + 0.035) + "]"});
  }
  return args;
}

}  // namespace rocklab::experiments::test
