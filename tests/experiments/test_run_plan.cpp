// Sweeps and studies as independent runs (issue 13): --plan + GNU parallel +
// collect gives the same table as --jobs 2; a resumed set redoes only what is
// missing; a failing variant is reported, not hidden.
#include <catch2/catch.hpp>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_support.h"

namespace fs = std::filesystem;

namespace {

int cli(std::vector<std::string> args) {
  // The run lines call the real rocklab executable, not this test binary.
  ::setenv("ROCKLAB_EXE", (fs::path(ROCKLAB_BINARY_DIR) / "app" / "rocklab").c_str(), 1);
  return rocklab::experiments::test::cli(std::move(args));
}

fs::path fresh(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rocklab-plan-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

std::vector<std::string> lines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// The first `columns` columns of a CSV (the deterministic ones: values and figures).
std::vector<std::string> leading(const fs::path& csv, int columns) {
  std::vector<std::string> out;
  for (const std::string& l : lines(csv)) {
    std::size_t pos = 0;
    for (int c = 0; c < columns && pos != std::string::npos; ++c) pos = l.find(',', pos + (c ? 1 : 0));
    out.push_back(l.substr(0, pos));
  }
  return out;
}

int shell(const std::string& command) { return std::system(command.c_str()); }

const std::vector<std::string> kSweep = {"sweep", "drop", "--vary", "timestep.safety_factor=0.5,0.3,0.2",
                                         "--metric", "restitution", "--metric", "drop.contact_time_s", "--quiet"};

}  // namespace

TEST_CASE("plan then GNU parallel then collect gives the table of --jobs 2", "[plan]") {
  REQUIRE(shell("command -v parallel > /dev/null") == 0);  // Debian's `parallel`, installed by scripts/setup.sh
  const fs::path planned = fresh("planned"), jobs = fresh("jobs");
  auto with = [](std::vector<std::string> a, std::vector<std::string> more) {
    a.insert(a.end(), more.begin(), more.end());
    return a;
  };
  REQUIRE(cli(with(kSweep, {"--plan", planned.string()})) == 0);
  for (const char* f : {"plan.json", "runs.txt", "slurm.sbatch", "README.md"}) CHECK(fs::exists(planned / f));
  CHECK_FALSE(fs::exists(planned / "runs"));  // nothing run
  const auto run_lines = lines(planned / "runs.txt");
  REQUIRE(run_lines.size() == 3);
  CHECK(run_lines[0].find(" run ") != std::string::npos);
  CHECK(run_lines[0].find("--set scene.seed=1") != std::string::npos);  // each run reproducible alone
  CHECK(run_lines[0].find("timestep.safety_factor=0.5") != std::string::npos);
  const auto sbatch = lines(planned / "slurm.sbatch");
  CHECK(std::find(sbatch.begin(), sbatch.end(), "#SBATCH --array=1-3") != sbatch.end());

  REQUIRE(shell("parallel --will-cite --jobs 2 < '" + (planned / "runs.txt").string() + "'") == 0);
  REQUIRE(cli({"collect", planned.string()}) == 0);
  REQUIRE(cli(with(kSweep, {"--jobs", "2", "--out", jobs.string()})) == 0);
  // Values and figures are the same, digit for digit (runs are deterministic).
  const auto a = leading(planned / "sweep.csv", 3), b = leading(jobs / "sweep.csv", 3);
  REQUIRE(a.size() == 4);
  CHECK(a == b);

  // Running the same list again is safe: every line sees a complete run and does nothing.
  const auto stamp = fs::last_write_time(planned / "runs" / "timestep.safety_factor=0.3" / "results.json");
  REQUIRE(shell("parallel --will-cite --jobs 2 < '" + (planned / "runs.txt").string() + "'") == 0);
  CHECK(fs::last_write_time(planned / "runs" / "timestep.safety_factor=0.3" / "results.json") == stamp);

  // Resuming after one run folder was deleted redoes that run only.
  fs::remove_all(jobs / "runs" / "timestep.safety_factor=0.2");
  const auto kept = fs::last_write_time(jobs / "runs" / "timestep.safety_factor=0.5" / "results.json");
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  REQUIRE(cli(with(kSweep, {"--jobs", "2", "--out", jobs.string()})) == 0);
  CHECK(fs::exists(jobs / "runs" / "timestep.safety_factor=0.2" / "results.json"));
  CHECK(fs::last_write_time(jobs / "runs" / "timestep.safety_factor=0.5" / "results.json") == kept);
  CHECK(leading(jobs / "sweep.csv", 3) == b);
  fs::remove_all(planned);
  fs::remove_all(jobs);
}

TEST_CASE("collect reports failed and missing runs and never hides them", "[plan]") {
  const fs::path dir = fresh("failing");
  // A value the scene refuses (exit 2) and a forced step far above critical that
  // the watchdog stops (exit 3), beside one good run.
  const int code = cli({"study", "drop", "--vary", "timestep.dt=1e-6,2e-4,-1", "--set", "timestep.allow_unsafe=true",
                        "--figure", "restitution", "--jobs", "2", "--out", dir.string(), "--quiet"});
  CHECK(code == 4);  // finished, some runs failed
  const auto table = lines(dir / "study.csv");
  REQUIRE(table.size() == 4);
  CHECK(table[1].find(",ok") != std::string::npos);
  CHECK(table[2].find("exit 3") != std::string::npos);
  CHECK(table[3].find("exit 2") != std::string::npos);
  CHECK(table[3].find("timestep.dt") != std::string::npos);  // the error says which key
  // A run that never ran is listed as missing.
  fs::remove_all(dir / "runs" / "timestep.dt=1e-6");
  fs::remove(dir / "logs" / "timestep.dt=1e-6.exit");
  CHECK(cli({"collect", dir.string()}) == 4);
  CHECK(lines(dir / "study.csv")[1].find("missing") != std::string::npos);
  CHECK(cli({"collect", (dir / "nowhere").string()}) == 2);
  fs::remove_all(dir);
}

TEST_CASE("a planned set leaves an invalid variant out of its run list, says why and exits 2", "[plan]") {
  const fs::path dir = fresh("invalid-plan");
  // timestep.dt = -1 is refused by the scene: no line for it, so GNU parallel or a
  // Slurm array never starts a run that can only fail; the valid ones are planned.
  CHECK(cli({"sweep", "drop", "--vary", "timestep.dt=1e-6,-1,2e-6", "--plan", dir.string(), "--quiet"}) == 2);
  const auto run_lines = lines(dir / "runs.txt");
  REQUIRE(run_lines.size() == 2);
  CHECK(run_lines[0].find("timestep.dt=1e-6") != std::string::npos);
  CHECK(run_lines[1].find("timestep.dt=2e-6") != std::string::npos);
  const auto sbatch = lines(dir / "slurm.sbatch");
  CHECK(std::find(sbatch.begin(), sbatch.end(), "#SBATCH --array=1-2") != sbatch.end());
  const auto log = lines(dir / "logs" / "timestep.dt=-1.log");
  REQUIRE_FALSE(log.empty());
  CHECK(log[0].find("timestep.dt") != std::string::npos);  // the message names the key
  CHECK(lines(dir / "logs" / "timestep.dt=-1.exit") == std::vector<std::string>{"2"});
  const auto readme = lines(dir / "README.md");
  CHECK(std::any_of(readme.begin(), readme.end(),
                    [](const std::string& l) { return l.find("`timestep.dt=-1`") != std::string::npos; }));
  // Every variant invalid: nothing is written at all.
  const fs::path none = fresh("all-invalid-plan");
  CHECK(cli({"sweep", "drop", "--vary", "timestep.dt=-1,-2", "--plan", none.string(), "--quiet"}) == 2);
  CHECK_FALSE(fs::exists(none));
  fs::remove_all(dir);
}

TEST_CASE("sweep --x-over: one number of a vector varied, plotted over a figure of each run, kept by collect", "[plan]") {
  // The drop height (the z of the pebble's position) over the contact time: the zoned chute's
  // CSS (walls.top.corner.2) over the clump's equivalent diameter works the same way.
  const fs::path dir = fresh("x-over");
  const std::vector<std::string> sweep = {"sweep", "drop", "--vary", "particles.0.positions.0.2=0.06,0.11", "--metric",
                                          "restitution", "--x-over", "drop.contact_time_s", "--jobs", "0",
                                          "--out", dir.string(), "--quiet"};
  REQUIRE(cli(sweep) == 0);
  // The divisor is tabulated beside the figures, and the plot's x is the value over it.
  const auto table = lines(dir / "sweep.csv");
  REQUIRE(table.size() == 3);
  CHECK(table[0] == "particles.0.positions.0.2,restitution,drop.contact_time_s,status");
  const auto plot = lines(dir / "sweep.plot.csv");
  REQUIRE(plot.size() == 3);
  CHECK(plot[0] == "series,particles.0.positions.0.2 / drop.contact_time_s,restitution");
  auto field = [](const std::string& row, int n) {
    std::size_t a = 0;
    for (int c = 0; c < n; ++c) a = row.find(',', a) + 1;
    return std::stod(row.substr(a, row.find(',', a) - a));
  };
  for (int r = 1; r <= 2; ++r) {
    const double height = field(table[r], 0), contact_time = field(table[r], 2);
    CHECK(height == (r == 1 ? 0.06 : 0.11));
    CHECK(contact_time > 0);
    CHECK(field(plot[r], 1) == Approx(height / contact_time).epsilon(1e-5));  // the table has 6 digits
  }
  // collect draws the same plot from plan.json.
  const auto before = lines(dir / "sweep.plot.csv");
  fs::remove(dir / "sweep.plot.csv");
  REQUIRE(cli({"collect", dir.string()}) == 0);
  CHECK(lines(dir / "sweep.plot.csv") == before);
  // samples follows the sets' --x-over: the x is the value over the divisor's mean.
  const fs::path second = fresh("x-over-2"), merged = fresh("x-over-samples"), plain = fresh("x-over-plain");
  auto with_out = [&](const fs::path& out, bool x_over) {
    std::vector<std::string> a = sweep;
    a[std::find(a.begin(), a.end(), "--out") - a.begin() + 1] = out.string();
    if (!x_over) a.erase(std::find(a.begin(), a.end(), "--x-over"), std::find(a.begin(), a.end(), "--x-over") + 2);
    return a;
  };
  REQUIRE(cli(with_out(second, true)) == 0);
  REQUIRE(cli({"samples", dir.string(), second.string(), "--out", merged.string()}) == 0);
  const auto merged_plot = lines(merged / "samples.plot.csv");
  REQUIRE(merged_plot.size() >= 3);
  CHECK(merged_plot[0].find("particles.0.positions.0.2 / drop.contact_time_s") != std::string::npos);
  CHECK(field(merged_plot[1], 1) == Approx(field(table[1], 0) / field(table[1], 2)).epsilon(1e-5));
  // Sets plotted against different x are not one figure: refused, naming both.
  REQUIRE(cli(with_out(plain, false)) == 0);
  CHECK(cli({"samples", dir.string(), plain.string(), "--out", (merged / "no").string()}) == 2);
  CHECK_FALSE(fs::exists(merged / "no"));
  for (const fs::path& d : {second, merged, plain}) fs::remove_all(d);
  // A key whose values are not numbers cannot be divided: refused before anything runs.
  const fs::path bad = fresh("x-over-bad");
  CHECK(cli({"sweep", "drop", "--vary", "particles.0.positions=[[0,0,0.06]],[[0,0,0.11]]", "--x-over",
             "drop.contact_time_s", "--out", bad.string(), "--quiet"}) == 2);
  CHECK_FALSE(fs::exists(bad));
  fs::remove_all(dir);
}

TEST_CASE("the Slurm array script on a local one-node Slurm gives the table of --jobs 2", "[plan][validation]") {
  // Starts (installing if needed) slurmctld + slurmd + munge on this machine.
  REQUIRE(shell("bash '" ROCKLAB_SOURCE_DIR "/scripts/local-slurm.sh' > /dev/null") == 0);
  const fs::path planned = fresh("slurm"), jobs = fresh("slurm-jobs");
  std::vector<std::string> plan = kSweep, local = kSweep;
  plan.insert(plan.end(), {"--plan", planned.string(), "--slurm-time", "00:10:00", "--slurm-mem", "1G"});
  local.insert(local.end(), {"--jobs", "2", "--out", jobs.string()});
  REQUIRE(cli(plan) == 0);
  REQUIRE(shell("sbatch --wait '" + (planned / "slurm.sbatch").string() + "' > /dev/null") == 0);
  REQUIRE(cli({"collect", planned.string()}) == 0);
  REQUIRE(cli(local) == 0);
  const auto a = leading(planned / "sweep.csv", 3);
  REQUIRE(a.size() == 4);
  CHECK(a == leading(jobs / "sweep.csv", 3));
  int slurm_logs = 0;  // one per array task
  for (const auto& e : fs::directory_iterator(planned / "logs")) slurm_logs += e.path().filename().string().rfind("slurm-", 0) == 0;
  CHECK(slurm_logs == 3);
  fs::remove_all(planned);
  fs::remove_all(jobs);
}

TEST_CASE("study --seeds: each variant runs once per seed and the table gives mean, scatter and error over scatter", "[plan]") {
  const fs::path dir = fresh("seeds");
  REQUIRE(cli({"study", "drop", "--vary", "timestep.safety_factor=0.4,0.2", "--figure", "restitution", "--seeds", "3",
               "--plan", dir.string()}) == 0);
  const auto run_lines = lines(dir / "runs.txt");
  REQUIRE(run_lines.size() == 6);  // 2 variants x 3 seeds, the seed fastest, from the scene's seed (1) up
  for (int k = 0; k < 6; ++k) CHECK(run_lines[k].find("--set scene.seed=" + std::to_string(1 + k % 3) + " ") != std::string::npos);
  CHECK(cli({"study", "drop", "--vary", "scene.seed=1,2", "--figure", "restitution", "--seeds", "2", "--plan",
             (dir / "both").string()}) == 2);
  // Stand-ins for six finished runs (the figures chosen so that the statistics are known):
  // variant 0.4: 0.70, 0.72, 0.74 (mean 0.72, sample sd 0.02); 0.2: 0.70, 0.70, 0.73 (0.71, sd 0.01732).
  const double figures[] = {0.70, 0.72, 0.74, 0.70, 0.70, 0.73};
  int k = 0;
  for (const char* sf : {"0.4", "0.2"})
    for (int seed = 1; seed <= 3; ++seed) {
      const fs::path run = dir / "runs" / ("timestep.safety_factor=" + std::string(sf) + "__scene.seed=" + std::to_string(seed));
      fs::create_directories(run);
      std::ofstream(run / "results.json") << "{\"status\": \"completed\", \"restitution\": " << figures[k++]
                                          << ", \"wall_time_s\": {\"total\": " << (sf[2] == '4' ? 1.0 : 2.0) << "}}";
    }
  REQUIRE(cli({"collect", dir.string()}) == 0);
  const auto table = lines(dir / "study.csv");
  REQUIRE(table.size() == 3);
  CHECK(table[0] == "timestep.safety_factor,restitution (mean),scatter,runs,error_over_scatter,error,error_pct,"
                    "wall_time_s (per run),pareto,reference,status");
  // 0.01 / sqrt(0.02^2/3 + 0.01732^2/3) = 0.6547
  CHECK(table[1].rfind("0.4,0.72,0.02,3,0.655,0.01,1.408,1,yes,,ok", 0) == 0);
  CHECK(table[2].rfind("0.2,0.71,0.01732,3,,0,0,2,", 0) == 0);
  std::ifstream in(dir / "study.json");
  const auto study = nlohmann::json::parse(in);
  CHECK(study["seeds"] == 3);
  CHECK(study["variants"][0]["runs"].size() == 3);
  CHECK(study["recommendation"].get<std::string>().find("the seeds cannot tell them apart") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("samples: sweeps of the same variants on three samples merge into mean, scatter, range and counts", "[plan]") {
  // A sample a sweep, as the zoned chute's cases restart from one deposit a sample. Stand-ins
  // for the runs, chosen so that the statistics are known:
  //   damping 0.1: restitution 0.70, 0.72, 0.74 (mean 0.72, sample sd 0.02); jammed in the third
  //   damping 0.2: 0.60, 0.64, and the third sample's run failed (mean 0.62, sd 0.0282843, 2 rows)
  //   damping 0.3: 0.50, none (the run completed without the figure), 0.56 (mean 0.53, sd 0.0424264)
  const fs::path dir = fresh("samples");
  const char* restitution[3][3] = {{"0.70", "0.60", "0.50"}, {"0.72", "0.64", "null"}, {"0.74", "", "0.56"}};
  const char* damping[3] = {"0.1", "0.2", "0.3"};
  for (int s = 0; s < 3; ++s) {
    const fs::path set = dir / ("s" + std::to_string(s + 1));
    REQUIRE(cli({"sweep", "drop", "--vary", "contact.damping_normal=0.1,0.2,0.3", "--metric", "restitution",
                 "--metric", "jammed", "--plan", set.string()}) == 0);
    for (int v = 0; v < 3; ++v) {
      const fs::path run = set / "runs" / ("contact.damping_normal=" + std::string(damping[v]));
      fs::create_directories(run);
      const std::string figure = restitution[s][v];
      std::ofstream(run / "results.json")
          << (figure.empty() ? std::string("{\"status\": \"failed\"}")
                             : "{\"status\": \"completed\", \"restitution\": " + figure + ", \"jammed\": " +
                                   (s == 2 && v == 0 ? "true" : "false") + "}");
    }
    CHECK(cli({"collect", set.string()}) == (s == 2 ? 4 : 0));  // the failed run: exit 4, its row not ok
  }
  const fs::path merged = dir / "merged";
  REQUIRE(cli({"samples", (dir / "s1").string(), (dir / "s2").string(), (dir / "s3").string(), "--label", "first",
               "--label", "second", "--label", "third", "--out", merged.string()}) == 0);
  const auto table = lines(merged / "samples.csv");
  REQUIRE(table.size() == 4);
  CHECK(table[0] == "contact.damping_normal,samples,restitution.mean,restitution.sd,restitution.min,restitution.max,"
                    "restitution.n,jammed.true,jammed.n");
  CHECK(table[1] == "0.1,3,0.72,0.02,0.7,0.74,3,1,3");
  CHECK(table[2] == "0.2,2,0.62,0.0282843,0.6,0.64,2,0,2");
  CHECK(table[3] == "0.3,3,0.53,0.0424264,0.5,0.56,2,0,3");
  const auto md = lines(merged / "samples.md");  // the same table for a report
  REQUIRE(md.size() >= 5);
  CHECK(md[0] == "| contact.damping_normal | samples | restitution | jammed |");
  CHECK(md[2] == "| 0.1 | 3 | 0.720 ± 0.020 (3) | 1/3 |");
  CHECK(md[3] == "| 0.2 | 2 | 0.620 ± 0.028 (2) | 0/2 |");
  CHECK(md[4] == "| 0.3 | 3 | 0.530 ± 0.042 (2) | 0/3 |");
  const nlohmann::json j = nlohmann::json::parse(rocklab::experiments::test::slurp(merged / "samples.json"));
  CHECK(j["samples"][2]["label"] == "third");
  CHECK(j["sets"][2]["runs_not_ok"] == 1);
  CHECK(j["variants"][1]["figures"]["restitution"]["per_sample"] == nlohmann::json::parse("[0.6, 0.64, null]"));
  CHECK(j["variants"][2]["figures"]["restitution"]["per_sample"] == nlohmann::json::parse("[0.5, null, 0.56]"));
  CHECK(j["variants"][0]["figures"]["jammed"]["per_sample"] == nlohmann::json::parse("[false, false, true]"));
  CHECK(fs::file_size(merged / "samples.png") > 1000);

  // Bad input: nothing written, exit 2, the message naming the file and what is allowed.
  const fs::path nothing = dir / "nothing";
  REQUIRE(cli({"sweep", "drop", "--vary", "timestep.safety_factor=0.4", "--metric", "restitution", "--plan",
               (dir / "other").string()}) == 0);
  std::string log;
  CHECK(rocklab::experiments::test::cliLogged(
            {"samples", (dir / "s1").string(), (dir / "other").string(), "--out", nothing.string()}, log) == 2);
  CHECK(log.find((dir / "other" / "sweep.csv").string()) != std::string::npos);  // planned, never collected
  CHECK(log.find("rocklab collect") != std::string::npos);
  fs::create_directories(dir / "other" / "runs" / "timestep.safety_factor=0.4");
  std::ofstream(dir / "other" / "runs" / "timestep.safety_factor=0.4" / "results.json")
      << "{\"status\": \"completed\", \"restitution\": 0.7}";
  REQUIRE(cli({"collect", (dir / "other").string()}) == 0);
  CHECK(rocklab::experiments::test::cliLogged(
            {"samples", (dir / "s1").string(), (dir / "other").string(), "--out", nothing.string()}, log) == 2);
  CHECK(log.find("varies timestep.safety_factor") != std::string::npos);
  CHECK(log.find("allowed: sweeps of the same keys") != std::string::npos);
  CHECK(rocklab::experiments::test::cliLogged(
            {"samples", (dir / "s1").string(), "--figure", "jammed", "--out", nothing.string()}, log) == 2);
  CHECK(log.find("allowed: a figure column with numbers: restitution") != std::string::npos);
  CHECK(rocklab::experiments::test::cliLogged(
            {"samples", (dir / "s1").string(), "--over", "scene.seed", "--out", nothing.string()}, log) == 2);
  CHECK(log.find("allowed: contact.damping_normal") != std::string::npos);
  CHECK(cli({"samples", (dir / "s1").string(), "--label", "a", "--label", "b", "--out", nothing.string()}) == 2);
  CHECK(cli({"samples", dir.string(), "--out", nothing.string()}) == 2);  // no plan.json
  CHECK_FALSE(fs::exists(nothing));
  fs::remove_all(dir);
}

TEST_CASE("samples --over scene.seed: the seeds one sweep varies are its samples", "[plan]") {
  // damping 0.1: seeds 1-3 give 0.70, 0.72, 0.74 (mean 0.72, sd 0.02); 0.2: 0.60, 0.64, 0.62 (0.62, 0.02).
  const fs::path dir = fresh("samples-over");
  REQUIRE(cli({"sweep", "drop", "--vary", "contact.damping_normal=0.1,0.2", "--vary", "scene.seed=1,2,3", "--metric",
               "restitution", "--plan", dir.string()}) == 0);
  const char* figures[2][3] = {{"0.70", "0.72", "0.74"}, {"0.60", "0.64", "0.62"}};
  for (int v = 0; v < 2; ++v)
    for (int seed = 1; seed <= 3; ++seed) {
      const fs::path run = dir / "runs" /
                           ("contact.damping_normal=" + std::string(v ? "0.2" : "0.1") + "__scene.seed=" + std::to_string(seed));
      fs::create_directories(run);
      std::ofstream(run / "results.json") << "{\"status\": \"completed\", \"restitution\": " << figures[v][seed - 1] << "}";
    }
  REQUIRE(cli({"collect", dir.string()}) == 0);
  REQUIRE(cli({"samples", dir.string(), "--over", "scene.seed", "--out", (dir / "merged").string()}) == 0);
  const auto table = lines(dir / "merged" / "samples.csv");
  REQUIRE(table.size() == 3);
  CHECK(table[0] == "contact.damping_normal,samples,restitution.mean,restitution.sd,restitution.min,restitution.max,"
                    "restitution.n");
  CHECK(table[1] == "0.1,3,0.72,0.02,0.7,0.74,3");
  CHECK(table[2] == "0.2,3,0.62,0.02,0.6,0.64,3");
  const nlohmann::json j = nlohmann::json::parse(rocklab::experiments::test::slurp(dir / "merged" / "samples.json"));
  CHECK(j["samples"][1]["label"] == "scene.seed = 2");
  CHECK(j["variants"][1]["figures"]["restitution"]["per_sample"] == nlohmann::json::parse("[0.6, 0.64, 0.62]"));
  fs::remove_all(dir);
}

namespace {

/// A set of samples over scene.seed (`rocklab samples --over`) from stand-in runs of
/// `values[damping][seed]` restitutions, at damping 0.1 and 0.2 (and, with `factors`,
/// each at those safety factors, one seed).
fs::path sampleSet(const fs::path& dir, const std::vector<std::vector<std::string>>& values,
                   const std::vector<std::string>& factors = {}) {
  const std::vector<std::string> damping{"0.1", "0.2"};
  std::vector<std::string> vary{"sweep", "drop", "--vary", "contact.damping_normal=0.1,0.2", "--vary",
                                factors.empty() ? "scene.seed=1,2,3" : "timestep.safety_factor=0.4,0.8",
                                "--metric", "restitution", "--plan", dir.string()};
  REQUIRE(cli(vary) == 0);
  for (std::size_t v = 0; v < damping.size(); ++v)
    for (std::size_t k = 0; k < values[v].size(); ++k) {
      const std::string second = factors.empty() ? "scene.seed=" + std::to_string(k + 1)
                                                 : "timestep.safety_factor=" + factors[k];
      const fs::path run = dir / "runs" / ("contact.damping_normal=" + damping[v] + "__" + second);
      fs::create_directories(run);
      std::ofstream(run / "results.json") << "{\"status\": \"completed\", \"restitution\": " << values[v][k] << "}";
    }
  REQUIRE(cli({"collect", dir.string()}) == 0);
  std::vector<std::string> merge{"samples", dir.string(), "--out", (dir / "merged").string()};
  if (factors.empty()) merge.insert(merge.end(), {"--over", "scene.seed"});
  REQUIRE(cli(merge) == 0);
  return dir / "merged";
}

}  // namespace

TEST_CASE("contrast: two sets of samples as the ratio or difference of their means, variant by variant, with the "
          "scatter of both",
          "[plan]") {
  // A: damping 0.1 gives 0.70, 0.72, 0.74 over three seeds (mean 0.72, sd 0.02), 0.2 gives
  // 0.60, 0.62, 0.64 (0.62, 0.02); B: 0.35, 0.36, 0.37 (0.36, 0.01) and 0.30, 0.31, 0.32
  // (0.31, 0.01). Ratio at 0.1: 2, scatter 2 sqrt((0.02/0.72)^2 + (0.01/0.36)^2) = 0.0785674;
  // difference 0.36, scatter sqrt(0.02^2 + 0.01^2) = 0.0223607.
  const fs::path dir = fresh("contrast");
  const fs::path a = sampleSet(dir / "a", {{"0.70", "0.72", "0.74"}, {"0.60", "0.62", "0.64"}});
  const fs::path b = sampleSet(dir / "b", {{"0.35", "0.36", "0.37"}, {"0.30", "0.31", "0.32"}});
  REQUIRE(cli({"contrast", a.string(), b.string(), "--out", (dir / "ratio").string()}) == 0);
  auto table = lines(dir / "ratio" / "contrast.csv");
  REQUIRE(table.size() == 3);
  CHECK(table[0] == "contact.damping_normal,restitution.value,restitution.scatter,restitution.n_a,restitution.n_b");
  CHECK(table[1] == "0.1,2,0.0785674,3,3");
  CHECK(table[2] == "0.2,2,0.0912396,3,3");
  CHECK(lines(dir / "ratio" / "contrast.md")[2] == "| 0.1 | 2 ± 0.0786 (3, 3) |");
  REQUIRE(cli({"contrast", a.string(), b.string(), "--op", "difference", "--out", (dir / "difference").string()}) == 0);
  table = lines(dir / "difference" / "contrast.csv");
  REQUIRE(table.size() == 3);
  CHECK(table[1] == "0.1,0.36,0.0223607,3,3");
  CHECK(table[2] == "0.2,0.31,0.0223607,3,3");
  const nlohmann::json j =
      nlohmann::json::parse(rocklab::experiments::test::slurp(dir / "difference" / "contrast.json"));
  CHECK(j["op"] == "difference");
  CHECK(j["variants"][0]["figures"]["restitution"]["a"]["mean"].get<double>() == Approx(0.72));
  CHECK(j["variants"][0]["figures"]["restitution"]["b"]["sd"].get<double>() == Approx(0.01));

  // C varies a key A does not (the safety factor), one sample a variant: fixed by --where,
  // its variants match A's on the damping; one sample has no scatter, so the contrast has none.
  const fs::path c = sampleSet(dir / "c", {{"0.36", "0.40"}, {"0.31", "0.35"}}, {"0.4", "0.8"});
  std::string log;
  CHECK(rocklab::experiments::test::cliLogged({"contrast", a.string(), c.string(), "--out", (dir / "x").string()},
                                              log) == 2);
  CHECK(log.find("two variants with contact.damping_normal = 0.1") != std::string::npos);
  CHECK(log.find("--where KEY=VALUE (its keys: timestep.safety_factor)") != std::string::npos);
  REQUIRE(cli({"contrast", a.string(), c.string(), "--where", "timestep.safety_factor=0.4", "--out",
               (dir / "where").string()}) == 0);
  table = lines(dir / "where" / "contrast.csv");
  REQUIRE(table.size() == 3);
  CHECK(table[1] == "0.1,2,,3,1");
  // Bad input: exit 2, the message naming what is allowed, nothing written.
  CHECK(rocklab::experiments::test::cliLogged({"contrast", a.string(), c.string(), "--where",
                                               "timestep.safety_factor=0.5", "--out", (dir / "x").string()},
                                              log) == 2);
  CHECK(log.find("allowed: 0.4, 0.8") != std::string::npos);
  CHECK(rocklab::experiments::test::cliLogged(
            {"contrast", a.string(), b.string(), "--where", "scene.seed=1", "--out", (dir / "x").string()}, log) == 2);
  CHECK(log.find("neither set varies scene.seed") != std::string::npos);
  CHECK(rocklab::experiments::test::cliLogged({"contrast", a.string(), dir.string(), "--out", (dir / "x").string()},
                                              log) == 2);
  CHECK(log.find((dir / "samples.json").string() + ": not found") != std::string::npos);
  CHECK(cli({"contrast", a.string(), "--out", (dir / "x").string()}) == 2);
  CHECK(cli({"contrast", a.string(), b.string(), "--op", "sum", "--out", (dir / "x").string()}) == 2);
  CHECK_FALSE(fs::exists(dir / "x"));
  fs::remove_all(dir);
}

TEST_CASE("samples.png leaves out a group in which no sample has the figure (every case jammed)", "[plan]") {
  // Two groups by the time-step factor; at 0.2 every run lacks the figure, as a zoned-chute
  // CSS whose every case jammed has no clearance time.
  const fs::path dir = fresh("samples-empty-group");
  REQUIRE(cli({"sweep", "drop", "--vary", "contact.damping_normal=0.1,0.2", "--vary", "timestep.safety_factor=0.4,0.2",
               "--vary", "scene.seed=1,2", "--metric", "restitution", "--plan", dir.string()}) == 0);
  for (const char* damping : {"0.1", "0.2"})
    for (const char* factor : {"0.4", "0.2"})
      for (const char* seed : {"1", "2"}) {
        const fs::path run = dir / "runs" /
                             (std::string("contact.damping_normal=") + damping + "__timestep.safety_factor=" + factor +
                              "__scene.seed=" + seed);
        fs::create_directories(run);
        std::ofstream(run / "results.json")
            << "{\"status\": \"completed\"" << (factor[2] == '4' ? std::string(", \"restitution\": 0.") + seed : "")
            << "}";
      }
  REQUIRE(cli({"collect", dir.string()}) == 0);
  REQUIRE(cli({"samples", dir.string(), "--over", "scene.seed", "--out", (dir / "merged").string()}) == 0);
  const std::string plotted = rocklab::experiments::test::slurp(dir / "merged" / "samples.plot.csv");
  CHECK(plotted.find("timestep.safety_factor = 0.4: each sample") != std::string::npos);
  CHECK(plotted.find("timestep.safety_factor = 0.2") == std::string::npos);
  const auto table = lines(dir / "merged" / "samples.csv");
  REQUIRE(table.size() == 5);
  CHECK(table[2] == "0.1,0.2,2,,,,,0");  // the empty group is still in the table, n = 0
  fs::remove_all(dir);
}

TEST_CASE("sweeps: two sweeps of one key side by side, each row's x over its own --x-over figure", "[plan]") {
  // As the zoned chute's single-size CSS sweeps, one deposit (so one sweep) a clump size, are
  // plotted against CSS / d_eq: the divisor differs between the sweeps. Stand-in runs:
  //   "small": contact time 0.01 s; damping 0.1 gives 0.7, at 0.2 no figure (a jammed case)
  //   "large": contact time 0.02 s; damping 0.1 gives 0.6, 0.2 gives 0.5
  const fs::path dir = fresh("sweeps");
  const char* figure[2][2] = {{"0.7", ""}, {"0.6", "0.5"}};
  for (int s = 0; s < 2; ++s) {
    const fs::path set = dir / (s ? "large" : "small");
    REQUIRE(cli({"sweep", "drop", "--vary", "contact.damping_normal=0.2,0.1", "--metric", "restitution", "--x-over",
                 "drop.contact_time_s", "--plan", set.string()}) == 0);
    for (int v = 0; v < 2; ++v) {
      const fs::path run = set / "runs" / (std::string("contact.damping_normal=") + (v ? "0.2" : "0.1"));
      fs::create_directories(run);
      std::ofstream(run / "results.json")
          << "{\"status\": \"completed\", \"drop\": {\"contact_time_s\": " << (s ? 0.02 : 0.01) << "}"
          << (*figure[s][v] ? std::string(", \"restitution\": ") + figure[s][v] : "") << "}";
    }
    REQUIRE(cli({"collect", set.string()}) == 0);
  }
  const fs::path out = dir / "both";
  REQUIRE(cli({"sweeps", (dir / "small").string(), (dir / "large").string(), "--out", out.string()}) == 0);
  const auto table = lines(out / "sweeps.csv");
  REQUIRE(table.size() == 5);  // a row a run, each sweep's rows by x
  CHECK(table[0] == "sweep,contact.damping_normal,restitution,drop.contact_time_s,status,"
                    "contact.damping_normal / drop.contact_time_s");
  CHECK(table[1] == "small,0.1,0.7,0.01,ok,10");
  CHECK(table[2] == "small,0.2,,0.01,ok,20");
  CHECK(table[3] == "large,0.1,0.6,0.02,ok,5");
  CHECK(table[4] == "large,0.2,0.5,0.02,ok,10");
  const std::string plotted = rocklab::experiments::test::slurp(out / "sweeps.plot.csv");
  CHECK(plotted.find("contact.damping_normal / drop.contact_time_s,restitution") != std::string::npos);
  CHECK(plotted.find("large,10,0.5") != std::string::npos);
  CHECK(plotted.find("small,20,nan") != std::string::npos);  // no figure: not drawn, the line breaks
  const nlohmann::json j = nlohmann::json::parse(rocklab::experiments::test::slurp(out / "sweeps.json"));
  CHECK(j["figure"] == "restitution");
  CHECK(j["sweeps"][1]["label"] == "large");
  CHECK(j["sweeps"][0]["rows"][1]["y"].is_null());
  // Bad input: exit 2, nothing written, the message says what is allowed.
  const fs::path nothing = dir / "nothing";
  std::string log;
  CHECK(rocklab::experiments::test::cliLogged(
            {"sweeps", (dir / "small").string(), "--figure", "status", "--out", nothing.string()}, log) == 2);
  CHECK(log.find("allowed: drop.contact_time_s, restitution") != std::string::npos);
  REQUIRE(cli({"sweep", "drop", "--vary", "contact.damping_normal=0.1", "--metric", "restitution", "--plan",
               (dir / "plain").string()}) == 0);
  std::ofstream((dir / "plain" / "sweep.csv")) << "contact.damping_normal,restitution,status\n0.1,0.7,ok\n";
  CHECK(rocklab::experiments::test::cliLogged(
            {"sweeps", (dir / "small").string(), (dir / "plain").string(), "--out", nothing.string()}, log) == 2);
  CHECK(log.find("allowed: sweeps") != std::string::npos);
  CHECK(cli({"sweeps", (dir / "small").string(), "--label", "a", "--label", "b", "--out", nothing.string()}) == 2);
  CHECK_FALSE(fs::exists(nothing));
  fs::remove_all(dir);
}

TEST_CASE("a stop signal to a sweep reaches its runs: each stops cleanly and says so", "[plan][cli]") {
  // Slurm's SIGTERM or a `kill` reaches the sweep's process only (its runs are process
  // groups of their own); it passes the stop on, so no run goes on orphaned.
  const fs::path dir = fresh("stop");
  const auto before = std::signal(SIGTERM, SIG_DFL);
  std::signal(SIGTERM, before);
  // The signal goes once both runs are under way: each has opened its run.h5.partial,
  // after its own stop handler was in place. (A fixed 2.5 s lost the race on a loaded
  // machine: a run still starting was killed by the default action, exit 143, with no
  // results.json.)
  std::thread sender([&dir] {
    for (const char* run : {"contact.damping_normal=0.1", "contact.damping_normal=0.2"})
      rocklab::experiments::test::waitUntilRunning(dir / "runs" / run);
    std::raise(SIGTERM);
  });
  const auto t0 = std::chrono::steady_clock::now();
  const int code = cli({"sweep", "hopper", "--vary", "contact.damping_normal=0.1,0.2", "--set", "scene.end_time=100",
                        "--jobs", "2", "--out", dir.string(), "--quiet"});
  sender.join();
  CHECK(code == 130);
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60));  // not 100 s of hopper each
  for (const char* run : {"contact.damping_normal=0.1", "contact.damping_normal=0.2"}) {
    INFO(run);
    const nlohmann::json r = nlohmann::json::parse(rocklab::experiments::test::slurp(dir / "runs" / run / "results.json"));
    CHECK(r["status"] == "interrupted");
    CHECK(lines(dir / "logs" / (std::string(run) + ".exit")) == std::vector<std::string>{"130"});
  }
  CHECK(std::signal(SIGTERM, before) == before);
  fs::remove_all(dir);
}

TEST_CASE("the rocklab executable runs its threads with a short OpenMP spin unless the user chose", "[cli]") {
  // Long-spinning waiters take a shared core from the working thread (app/main.cpp); the
  // executable sets GOMP_SPINCOUNT=1000 for itself, and keeps a user's own choice.
  const std::string exe = (fs::path(ROCKLAB_BINARY_DIR) / "app" / "rocklab").string();
  const fs::path dir = fresh("wait");
  const std::string run = exe + " run drop --quiet --threads 2 --set scene.end_time=0.001 --overwrite --out ";
  REQUIRE(shell("env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT " + run + (dir / "own").string()) == 0);
  REQUIRE(shell("env -u GOMP_SPINCOUNT OMP_WAIT_POLICY=active " + run + (dir / "user").string()) == 0);
  const auto waitOf = [&](const char* name) {
    return nlohmann::json::parse(rocklab::experiments::test::slurp(dir / name / "results.json"))["openmp_wait"];
  };
  CHECK(waitOf("own") == "GOMP_SPINCOUNT=1000");
  CHECK(waitOf("user") == "OMP_WAIT_POLICY=active");
  fs::remove_all(dir);
}
