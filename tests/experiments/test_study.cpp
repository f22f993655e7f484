// rocklab study: errors against a reference, the Pareto front, the recommendation,
// and the command end to end on the drop test.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "rocklab/experiments/scene.h"
#include "rocklab/experiments/study.h"

namespace fs = std::filesystem;
using namespace rocklab::experiments;

namespace {

StudyPoint point(double figure, double wall, bool ok = true) {
  StudyPoint p;
  p.figure = figure;
  p.wall_s = wall;
  p.ok = ok;
  return p;
}

using rocklab::experiments::test::cli;

}  // namespace

TEST_CASE("study analysis: errors against the finest - Pareto front - converged recommendation", "[study]") {
  // Cheapest to finest. The first lands near the reference by chance; the
  // second and third are off; from the fourth on everything is within 1 %.
  const StudyAnalysis a = analyseStudy(
      {point(1.004, 1), point(1.05, 2), point(0.97, 3), point(1.008, 4), point(1.002, 8), point(1.0, 16)},
      std::nullopt, 1.0);
  REQUIRE(a.points.size() == 6);
  CHECK(a.reference == 1.0);
  CHECK(a.points[5].is_reference);
  CHECK(a.points[1].error_pct == Approx(5.0));
  CHECK(a.points[2].error == Approx(0.03));
  // Pareto: 1 (cheapest, 0.4 %), 5 (0.2 %), 6 (0); 2, 3, 4 are dominated by 1.
  CHECK(a.points[0].pareto);
  CHECK_FALSE(a.points[1].pareto);
  CHECK_FALSE(a.points[2].pareto);
  CHECK_FALSE(a.points[3].pareto);
  CHECK(a.points[4].pareto);
  CHECK(a.points[5].pareto);
  // Not the lucky first variant: the fourth, from which on all are within 1 %.
  REQUIRE(a.recommended);
  CHECK(*a.recommended == 3);

  // A lab value as the reference; a failed run is skipped, never the reference.
  const StudyAnalysis lab = analyseStudy({point(25.0, 1), point(26.0, 2), point(std::nan(""), 3, false)}, 26.03, 0.5);
  CHECK(lab.reference == 26.03);
  CHECK_FALSE(lab.points[1].is_reference);
  CHECK(std::isnan(lab.points[2].error));
  CHECK_FALSE(lab.points[2].pareto);
  REQUIRE(lab.recommended);
  CHECK(*lab.recommended == 1);
  // Nothing within the tolerance: no recommendation.
  CHECK_FALSE(analyseStudy({point(25.0, 1), point(24.0, 2)}, 26.03, 0.5).recommended);
}

TEST_CASE("study command: drop restitution against the time step", "[study][cli]") {
  const fs::path out = fs::temp_directory_path() / "rocklab-study-drop";
  fs::remove_all(out);
  // In this process, one run after the other (the process pool is tested in test_run_plan.cpp).
  REQUIRE(cli({"study", "drop", "--vary", "timestep.safety_factor=0.5,0.2,0.05", "--figure", "restitution",
               "--tolerance", "1", "--jobs", "0", "--out", out.string(), "--quiet"}) == 0);
  for (const char* f : {"study.csv", "study.json", "study.png", "plan.json", "runs.txt",
                        "runs/timestep.safety_factor=0.5/results.json", "runs/timestep.safety_factor=0.05/results.json"})
    CHECK(fs::exists(out / f));
  std::ifstream in(out / "study.json");
  const nlohmann::json s = nlohmann::json::parse(in);
  INFO(s.dump(2));
  REQUIRE(s["variants"].size() == 3);
  CHECK(s["reference"]["kind"] == "finest");
  // The finest step is the reference; the restitution converges to it (Eq 4-4: 0.7063).
  CHECK(s["variants"][2]["reference"] == true);
  CHECK(s["reference"]["value"].get<double>() == Approx(0.7063).epsilon(0.01));
  CHECK(s["variants"][0]["error_pct"].get<double>() > s["variants"][1]["error_pct"].get<double>());
  CHECK(s["variants"][0]["wall_time_s"].get<double>() > 0);
  CHECK(s["recommendation"].get<std::string>().find("timestep.safety_factor") != std::string::npos);

  // A lab value as the reference.
  REQUIRE(cli({"study", "drop", "--vary", "timestep.safety_factor=0.5,0.2", "--figure", "restitution",
               "--reference", "0.7063", "--jobs", "0", "--out", (out / "lab").string(), "--quiet"}) == 0);
  std::ifstream in2(out / "lab" / "study.json");
  const nlohmann::json lab = nlohmann::json::parse(in2);
  CHECK(lab["reference"]["value"].get<double>() == 0.7063);
  CHECK(lab["variants"][1]["reference"] == false);
}

TEST_CASE("study: bad input is refused before any run", "[study][cli]") {
  const fs::path out = fs::temp_directory_path() / "rocklab-study-bad";
  fs::remove_all(out);
  // No valid variant, no figure, a bad reference: exit 2, nothing written.
  CHECK(cli({"study", "drop", "--vary", "timestep.safety_factor=-1,2", "--figure", "restitution", "--jobs", "0",
             "--out", out.string(), "--quiet"}) == 2);
  CHECK(cli({"study", "drop", "--vary", "timestep.safety_factor=0.5", "--jobs", "0", "--out", out.string(), "--quiet"}) == 2);
  CHECK(cli({"study", "drop", "--vary", "timestep.safety_factor=0.5", "--figure", "restitution", "--reference",
             "fine", "--jobs", "0", "--out", out.string(), "--quiet"}) == 2);
  CHECK_FALSE(fs::exists(out));
  // One bad value among good ones: it is listed as failed (exit 2, its message) and
  // costs nothing; the others run; the command says some runs failed (exit 4).
  CHECK(cli({"study", "drop", "--vary", "timestep.safety_factor=0.5,-1", "--figure", "restitution", "--jobs", "0",
             "--out", out.string(), "--quiet"}) == 4);
  std::ifstream csv(out / "study.csv");
  std::string header, good, bad;
  std::getline(csv, header);
  std::getline(csv, good);
  std::getline(csv, bad);
  CHECK(good.find(",ok") != std::string::npos);
  CHECK(bad.find("exit 2: --set timestep.safety_factor=-1") != std::string::npos);
  CHECK_FALSE(fs::exists(out / "runs" / "timestep.safety_factor=-1"));
  fs::remove_all(out);
  // A study file with an unknown key names the file and the key.
  const fs::path file = fs::temp_directory_path() / "rocklab-bad-study.toml";
  std::ofstream(file) << "[study]\nscene = \"drop\"\nfigure = \"restitution\"\ntolerence_pct = 1\n"
                         "[[study.vary]]\nkey = \"timestep.safety_factor\"\nvalues = [0.5, 0.2]\n";
  CHECK_THROWS_WITH(loadStudyFile(file), Catch::Contains("tolerence_pct") && Catch::Contains("rocklab-bad-study.toml"));
  CHECK(cli({"study", file.string(), "--out", out.string(), "--quiet"}) == 2);
}

TEST_CASE("every built-in study file loads and names a scene that loads", "[study]") {
  int n = 0;
  for (const auto& e : fs::directory_iterator(builtinStudyDir())) {
    if (e.path().extension() != ".toml") continue;
    INFO(e.path());
    const StudyOptions o = loadStudyFile(e.path());
    CHECK_FALSE(o.figure.empty());
    CHECK_FALSE(o.runs.vary.empty());
    CHECK(findStudyFile(e.path().stem().string()));
    // ...and its scene loads with the study's settings, at the cheapest and the
    // finest value of every varied key (each run of the study is one of these
    // corners or between them): a renamed key or a bad value fails here.
    REQUIRE_FALSE(o.runs.scene.empty());
    for (std::size_t end : {0, 1}) {
      std::vector<std::string> overrides = o.runs.overrides;
      for (const auto& [key, values] : o.runs.vary) {
        REQUIRE_FALSE(values.empty());
        overrides.push_back(key + "=" + (end == 0 ? values.front() : values.back()));
      }
      INFO("scene " << o.runs.scene << " with " << overrides.size() << " settings, " << (end ? "finest" : "cheapest"));
      const Scene scene = loadScene(resolveScene(o.runs.scene), overrides);
      CHECK((scene.spheres.size() + scene.clumps.size()) > 0);
    }
    ++n;
  }
  CHECK(n >= 1);
}
