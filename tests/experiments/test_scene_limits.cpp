// Scene values that are in range one by one but unusable: a name that is a path,
// triangle indices that are not indices, particle counts past what memory or random
// insertion allows. Each class: one message with file:line, key, value and why.
#include <catch2/catch.hpp>
#include <filesystem>
#include <string>

#include "rocklab/experiments/scene.h"

using namespace rocklab::experiments;
using Catch::Contains;

namespace {

const std::string kMaterial = "[materials.rock]\ndensity = 2730\nkn = 1e7\n";

std::string scene(const std::string& name, const std::string& rest) {
  return "[scene]\nname = " + name + "\nend_time = 0.01\n\n" + kMaterial + rest;
}

const std::string kOneBall = "\n[[particles]]\ntype = \"list\"\nmaterial = \"rock\"\nradius = 0.01\npositions = [[0, 0, 0.1]]\n";

std::string errorOf(const std::string& text) {
  try {
    loadSceneText(text, "bad.toml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("names that become output paths are names, not paths", "[scene]") {
  // Without --out the run writes to out/NAME: a path would write anywhere.
  for (const std::string name : {R"("/somewhere")", R"("../../x")", R"("a/b")", R"("")", R"("..")", R"("a\u0001b")",
                                 R"("a\\b")"}) {
    INFO(name);
    const std::string msg = errorOf(scene(name, kOneBall));
    CHECK_THAT(msg, Contains("bad.toml:2: key 'scene.name' = "));
    CHECK((msg.find("path") != std::string::npos || msg.find("empty") != std::string::npos ||
           msg.find("control") != std::string::npos || msg.find("not a name") != std::string::npos));
  }
  CHECK(loadSceneText(scene(R"("chute-30_clumps.v2")", kOneBall), "ok.toml").run.name == "chute-30_clumps.v2");
  // A camera's name makes NAME.mp4 and frames/NAME/.
  CHECK_THAT(errorOf(scene("\"t\"", kOneBall + "\n[[cameras]]\nname = \"../../side\"\nfov_deg = 60.0\n"
                                                "eye = [0, 0, 1]\ntarget = [0, 0, 0]\nup = [1, 0, 0]\n")),
             Contains("key 'cameras.0.name' = \"../../side\": is a name, not a path"));
}

TEST_CASE("mesh wall triangles are whole vertex indices within the vertices", "[scene]") {
  auto wall = [](const std::string& triangles) {
    return scene("\"t\"", kOneBall + "\n[[walls]]\ntype = \"mesh\"\nmaterial = \"rock\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n"
                                    "triangles = " + triangles + "\n");
  };
  // 0.7, 1.2, 2.9 used to read as 0, 1, 2 and 4294967298 to wrap to 2.
  for (const std::string bad : {"[[0.7, 1.2, 2.9]]", "[[0, 1, 4294967298]]", "[[0, 1, 3]]", "[[-1, 1, 2]]",
                                "[[0, 1]]", "[[0, 1, \"2\"]]"}) {
    INFO(bad);
    const std::string msg = errorOf(wall(bad));
    CHECK_THAT(msg, Contains("bad.toml:") && Contains("key 'walls.0.triangles'") && Contains("entry 0"));
  }
  CHECK_THAT(errorOf(wall("[[0.7, 1.2, 2.9]]")), Contains("0.7 is not a vertex index; allowed: whole numbers 0 to 2"));
  CHECK(loadSceneText(wall("[[0, 1, 2]]"), "ok.toml").model.walls.size() == 1);
  CHECK(loadSceneText(wall("[[0.0, 1.0, 2.0]]"), "ok.toml").model.walls.size() == 1);  // whole floats are indices
}

TEST_CASE("particle sources stay within the ball cap and what random insertion reaches", "[scene]") {
  // Refused before anything is allocated, with the memory it would take: these used to
  // die in std::bad_alloc or insert for minutes with no output.
  const std::string lattice = "\n[[particles]]\ntype = \"lattice\"\nmaterial = \"rock\"\nradius = 0.001\n"
                              "cell = 0.002\ncounts = [10000, 10000, 10000]\n";
  std::string msg = errorOf(scene("\"t\"", lattice));
  CHECK_THAT(msg, Contains("bad.toml:") && Contains("key 'particles.0.counts'") && Contains("1e+12 balls") &&
                      Contains("GB of memory") && Contains("at most 1e+07 balls"));
  // 0.25 of a 1 m box in 0.4 mm spheres is 2.3e9 spheres: over the cap, refused at once.
  const std::string random = "\n[[particles]]\ntype = \"random\"\nmaterial = \"rock\"\nradius = 0.0004\n"
                             "region_min = [0, 0, 0]\nregion_max = [1, 1, 1]\n";
  msg = errorOf(scene("\"t\"", random + "solid_fraction = 0.25\n"));
  CHECK_THAT(msg, Contains("key 'particles.0.solid_fraction'") && Contains("at most 1e+07 balls"));
  // 0.59 is above what random insertion can reach: said so, whatever the count.
  msg = errorOf(scene("\"t\"", random + "solid_fraction = 0.59\n"));
  CHECK_THAT(msg, Contains("key 'particles.0.solid_fraction' = 0.5") && Contains("above what random insertion reaches"));
  // An HCP agglomerate is counted before it is packed (a 100 m one hung in the packing).
  try {
    loadScene(resolveScene("zwick-hcp"), {"particles.0.diameter=100"});
    FAIL("no error");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Contains("key 'particles.0.diameter'") && Contains("spheres of radius 0.0025 m") &&
                             Contains("at most 2e6"));
  }
  // A reachable fraction that does not fit says how far insertion got.
  msg = errorOf(scene("\"t\"", "\n[[particles]]\ntype = \"random\"\nmaterial = \"rock\"\nradius = 0.01\n"
                               "region_min = [0, 0, 0]\nregion_max = [0.2, 0.2, 0.2]\nsolid_fraction = 0.3\n"));
  CHECK_THAT(msg, Contains("spheres fit in the region without overlap (random insertion stopped at a solid fraction of 0."));
}

TEST_CASE("a built-in scene's name opens the built-in even where a folder of that name exists", "[scene]") {
  // `rocklab run drop --out drop`, then `rocklab run drop` in the same folder: the
  // outputs' folder shadowed the built-in ("drop: is a directory, not a scene file").
  namespace fs = std::filesystem;
  const fs::path here = fs::current_path();
  const fs::path dir = fs::temp_directory_path() / "rocklab-builtin-shadow";
  fs::remove_all(dir);
  fs::create_directories(dir / "drop");
  fs::current_path(dir);
  const fs::path resolved = resolveScene("drop");
  const fs::path missing = resolveScene("no-such-scene");
  fs::create_directories(dir / "mine");
  std::string folder_error;
  try {
    loadScene(resolveScene("mine"), {});
  } catch (const SceneError& e) {
    folder_error = e.what();
  }
  fs::current_path(here);
  fs::remove_all(dir);
  CHECK(resolved == builtinSceneDir() / "drop.toml");
  CHECK(missing == fs::path("no-such-scene"));
  // A folder that is no built-in's name is still refused as a folder.
  CHECK_THAT(folder_error, Contains("mine: is a directory, not a scene file"));
}
