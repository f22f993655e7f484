// The CLI in-process: exit codes, outputs, and "bad input loses nothing".
#include <H5Cpp.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <csignal>
#include <thread>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "rocklab/sim/output/checkpoint.h"

namespace fs = std::filesystem;

namespace {
using rocklab::experiments::test::cli;
using rocklab::experiments::test::slurp;
using rocklab::experiments::test::waitUntilRunning;
fs::path tempDir(const std::string& name) {
  // The pid keeps two checkouts' suites running at once apart.
  const fs::path d = fs::temp_directory_path() / ("rocklab-cli-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}
const std::string kScene = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/hopper.toml";
/// The exit code and what the command printed on stderr.
std::pair<int, std::string> cliStderr(const std::vector<std::string>& args) {
  std::ostringstream log;
  auto* const old = std::cerr.rdbuf(log.rdbuf());
  const int code = cli(args);
  std::cerr.rdbuf(old);
  return {code, log.str()};
}
}  // namespace

TEST_CASE("help and usage errors", "[cli]") {
  CHECK(cli({"--help"}) == 0);
  CHECK(cli({}) == 2);
  CHECK(cli({"run"}) == 2);
  CHECK(cli({"frobnicate"}) == 2);
}

TEST_CASE("a short run writes run.h5 - checkpoint - vtk and results.json", "[cli]") {
  const fs::path out = tempDir("run");
  REQUIRE(cli({"run", kScene, "--out", out.string(), "--quiet", "--set", "scene.end_time=0.002", "--set",
               "particles.0.count=200", "--set", "output.frame_interval=0.001"}) == 0);
  for (const char* f : {"run.h5", "checkpoint.h5", "results.json", "vtk/particles.pvd"}) CHECK(fs::exists(out / f));
  const auto r = nlohmann::json::parse(slurp(out / "results.json"));
  CHECK(r["status"] == "completed");
  CHECK(r["particles"] == 200);
  CHECK(r["outputs"]["frames"] == 3);  // t = 0, 0.001 and the last step
  CHECK(r["wall_time_s"]["stepping"].get<double>() > 0);
  // The time-step report: the damped limit and the contact-network checks (every 1000 steps).
  CHECK(r["timestep"]["damped_limit_s"].get<double>() > r["timestep"]["automatic_s"].get<double>());
  CHECK(r["timestep"]["network_checks"].get<int>() == (r["steps"].get<int>() + 999) / 1000);
  CHECK(r["timestep"]["network_step_ratio_max"].get<double>() < 1.0);

  // Restart from the checkpoint continues to a later end time.
  const fs::path out2 = tempDir("restart");
  REQUIRE(cli({"restart", (out / "checkpoint.h5").string(), "--out", out2.string(), "--quiet", "--set",
               "scene.end_time=0.003"}) == 0);
  const auto r2 = nlohmann::json::parse(slurp(out2 / "results.json"));
  CHECK(r2["simulated_time_s"].get<double>() == Approx(0.003).margin(2e-6));
  // ...bit for bit: the same state as a run straight to 0.003 s.
  const fs::path out3 = tempDir("straight");
  REQUIRE(cli({"run", kScene, "--out", out3.string(), "--quiet", "--set", "scene.end_time=0.003", "--set",
               "particles.0.count=200", "--set", "output.frame_interval=0.001"}) == 0);
  const auto r3 = nlohmann::json::parse(slurp(out3 / "results.json"));
  CHECK(r2["steps"] == r3["steps"]);
  CHECK(r2["state_hash"].get<std::string>() == r3["state_hash"].get<std::string>());
  CHECK(r["state_hash"].get<std::string>() != r3["state_hash"].get<std::string>());  // the hash sees the motion
  fs::remove_all(out);
  fs::remove_all(out2);
  fs::remove_all(out3);
}

TEST_CASE("bad input: exit code 2 and the previous outputs are untouched", "[cli]") {
  const fs::path out = tempDir("bad");
  fs::create_directories(out);
  std::ofstream(out / "results.json") << "{\"previous\": true}\n";
  CHECK(cli({"run", kScene, "--out", out.string(), "--set", "timestep.safety_factor=7"}) == 2);
  CHECK(cli({"run", kScene, "--out", out.string(), "--set", "timestep.dt=1"}) == 2);
  CHECK(cli({"run", "/no/such/scene.toml", "--out", out.string()}) == 2);
  CHECK(cli({"check", "heap", "--set", "experiment.check_interval=0.002"}) == 2);  // renamed key
  CHECK(cli({"restart", "/no/such/checkpoint.h5", "--out", out.string()}) == 2);
  CHECK(slurp(out / "results.json") == "{\"previous\": true}\n");
  CHECK(!fs::exists(out / "run.h5"));
  fs::remove_all(out);
}

TEST_CASE("command-line messages: short ranges - the value that is not a number - a folder is no scene", "[cli]") {
  const auto [threads_code, threads] = cliStderr({"run", kScene, "--threads", "-1"});
  CHECK(threads_code == 2);
  CHECK_THAT(threads, Catch::Contains("--threads") && Catch::Contains("not in range 0 to 4096"));
  CHECK(threads.size() < 200);  // not the largest double in 309 digits
  const auto [target_code, target] =
      cliStderr({"calibrate", "drop", "--vary", "contact.damping_normal=0:0.4", "--target", "restitution=abc"});
  CHECK(target_code == 2);
  CHECK_THAT(target, Catch::Contains("--target restitution=abc: 'abc' is not a number"));
  // A folder where a file belongs: said so by every command that reads one.
  const std::string folder = fs::temp_directory_path().string();
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"check", folder}, {"restart", folder, "--out", tempDir("dir").string()},
        {"render", folder, "--out", tempDir("dir").string()},
        {"shape", folder, "--out", tempDir("dir").string(), "--no-preview"}}) {
    const auto [dir_code, dir] = cliStderr(args);
    CHECK(dir_code == 2);
    CHECK_THAT(dir, Catch::Contains("is a directory"));
  }
}

TEST_CASE("a quiet run (option quiet) prints nothing when good and its error when bad", "[cli]") {
  const fs::path out = tempDir("quiet");
  const auto [code, log] = cliStderr({"run", kScene, "--out", out.string(), "--quiet", "--set", "scene.end_time=0.001",
                                      "--set", "particles.0.count=20", "--set", "output.hdf5=false"});
  CHECK(code == 0);
  CHECK(log.empty());  // not the time-step audit, not the summary
  const auto [bad_code, bad] = cliStderr({"run", kScene, "--out", out.string(), "--quiet", "--set", "foo.bar=1"});
  CHECK(bad_code == 2);
  CHECK_THAT(bad, Catch::Contains("error: --set foo.bar=1: unknown key 'foo'"));
  fs::remove_all(out);
}

TEST_CASE("check and list", "[cli]") {
  CHECK(cli({"check", kScene}) == 0);
  CHECK(cli({"list"}) == 0);
}

TEST_CASE("check prints the step the run takes with the bonds' springs", "[cli]") {
  // zwick-hcp's bonds are stiffer than its contacts: check once left them out and
  // printed a step six times the run's.
  std::ostringstream printed;
  auto* const old = std::cout.rdbuf(printed.rdbuf());
  const int code = cli({"check", "zwick-hcp"});
  std::cout.rdbuf(old);
  REQUIRE(code == 0);
  const std::string text = printed.str();
  const auto at = text.find("chosen dt");
  REQUIRE(at != std::string::npos);
  const double printed_dt = std::stod(text.substr(text.find_first_of("0123456789", at)));
  const fs::path out = tempDir("check-dt");
  REQUIRE(cli({"run", "zwick-hcp", "--out", out.string(), "--quiet", "--set", "scene.end_time=1e-5"}) == 0);
  std::ifstream in(out / "results.json");
  const double run_dt = nlohmann::json::parse(in)["dt_s"].get<double>();
  CHECK(printed_dt == Approx(run_dt).epsilon(1e-3));  // printed to four digits
  fs::remove_all(out);
}

TEST_CASE("Ctrl-C stops cleanly: exit 130 and readable run.h5 - checkpoint and results", "[cli]") {
  const fs::path out = tempDir("sigint");
  std::thread interrupter([&out] {
    waitUntilRunning(out);
    std::raise(SIGINT);  // the handler runCli installed turns it into a clean stop
  });
  const int code = cli({"run", kScene, "--out", out.string(), "--quiet", "--set", "scene.end_time=100"});
  interrupter.join();
  CHECK(code == 130);
  const auto r = nlohmann::json::parse(slurp(out / "results.json"));
  CHECK(r["status"] == "interrupted");
  CHECK(r["simulated_time_s"].get<double>() < 100);
  H5::H5File file((out / "run.h5").string(), H5F_ACC_RDONLY);
  CHECK(file.openGroup("frames").getNumObjs() >= 1);
  int interrupted = 0;
  file.openAttribute("interrupted").read(H5::PredType::NATIVE_INT, &interrupted);
  CHECK(interrupted == 1);
  file.close();
  // The checkpoint holds the state the run stopped in, and a restart goes on from it.
  const auto cp = rocklab::sim::output::readCheckpoint(out / "checkpoint.h5");
  CHECK(cp.state.time == r["simulated_time_s"].get<double>());
  CHECK(cp.state.step == r["steps"].get<std::uint64_t>());
  const double more = cp.state.time + 0.001;
  const fs::path out2 = tempDir("sigint-restart");
  REQUIRE(cli({"restart", (out / "checkpoint.h5").string(), "--out", out2.string(), "--quiet", "--set",
               "scene.end_time=" + std::to_string(more)}) == 0);
  const auto r2 = nlohmann::json::parse(slurp(out2 / "results.json"));
  CHECK(r2["status"] == "completed");
  CHECK(r2["steps"].get<std::uint64_t>() > cp.state.step);
  CHECK(r2["simulated_time_s"].get<double>() == Approx(more).margin(2e-6));
  // The wall time goes on with the run: the checkpoint holds what the first run took
  // up to it, the restart reports it beside its own.
  REQUIRE(std::isfinite(cp.run_wall_time_s));
  CHECK(cp.run_wall_time_s > 0);
  CHECK(cp.run_wall_time_s <= r["wall_time_s"]["total"].get<double>());
  CHECK(r["wall_time_s"]["earlier_runs"] == 0.0);  // a new run continues none
  CHECK(r2["wall_time_s"]["earlier_runs"].get<double>() == cp.run_wall_time_s);
  CHECK(r2["wall_time_s"]["all_runs"].get<double>() ==
        Approx(cp.run_wall_time_s + r2["wall_time_s"]["total"].get<double>()).epsilon(1e-12));
  fs::remove_all(out);
  fs::remove_all(out2);
}

TEST_CASE("a second Ctrl-C ends the process at once", "[cli]") {
  // In a child process (the test's own would die): a run on one thread (no
  // OpenMP team is forked) is interrupted twice in a row. raise() runs the
  // handler in the raising thread before it returns, so the second signal comes
  // after the first was handled and while the run is still stopping.
  const fs::path out = tempDir("sigint2");
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    std::thread interrupter([&out] {
      waitUntilRunning(out);
      std::raise(SIGINT);  // clean stop requested
      std::raise(SIGINT);  // the second kills
    });
    const int code = cli({"run", kScene, "--out", out.string(), "--quiet", "--threads", "1", "--set",
                          "scene.end_time=100"});
    interrupter.join();
    ::_exit(code == 130 ? 40 : 41);  // only reached when the second Ctrl-C did not kill
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  INFO("exit status " << (WIFEXITED(status) ? WEXITSTATUS(status) : -1));
  CHECK(WIFSIGNALED(status));
  CHECK((WIFSIGNALED(status) && WTERMSIG(status) == SIGINT));
  fs::remove_all(out);
}

TEST_CASE("restart refuses an experiment scene that saves no state and writes nothing", "[cli]") {
  // The drop test's phase is not in the checkpoint (only the crusher's driver saves
  // its state): continuing would run it from its first phase on a later state.
  const fs::path out = tempDir("drop"), out2 = tempDir("drop-restart");
  REQUIRE(cli({"run", "drop", "--out", out.string(), "--quiet", "--set", "scene.end_time=0.01", "--set",
               "output.checkpoint=true"}) == 0);
  REQUIRE(fs::exists(out / "checkpoint.h5"));
  const auto [code, log] = cliStderr({"restart", (out / "checkpoint.h5").string(), "--out", out2.string(),
                                      "--quiet", "--set", "scene.end_time=0.02"});
  CHECK(code == 2);
  CHECK_THAT(log, Catch::Contains("experiment.drop scenes cannot be restarted from a checkpoint"));
  CHECK_THAT(log, Catch::Contains("error: checkpoint '" + (out / "checkpoint.h5").string() + "': "));  // names the file
  CHECK_FALSE(fs::exists(out2));
  fs::remove_all(out);
}

TEST_CASE("render re-renders a stored run from another camera", "[cli]") {
  const fs::path out = tempDir("render");
  REQUIRE(cli({"run", kScene, "--out", out.string(), "--quiet", "--set", "scene.end_time=0.004", "--set",
               "particles.0.count=200", "--set", "output.frame_interval=0.001"}) == 0);
  const fs::path camera = out / "top.toml";
  std::ofstream(camera) << "[[cameras]]\nname = \"top\"\nresolution = [320, 240]\nfov_deg = 60.0\n"
                           "eye = [0.0, 0.0, 1.5]\ntarget = [0.0, 0.0, 0.3]\nup = [1.0, 0.0, 0.0]\n";
  REQUIRE(cli({"render", (out / "run.h5").string(), "--camera", camera.string(), "--out", (out / "top").string()}) == 0);
  const fs::path movie = fs::exists(out / "top" / "top.mp4") ? out / "top" / "top.mp4" : out / "top" / "top.avi";
  REQUIRE(fs::exists(movie));
  CHECK(fs::file_size(movie) > 0);
  // A camera's start_time and end_time pick the stored frames (every 0.001 s): those
  // at 0.002 and 0.003 s.
  std::ofstream(out / "window.toml") << "[[cameras]]\nname = \"window\"\nresolution = [64, 48]\nfov_deg = 60.0\n"
                                        "eye = [0.0, 0.0, 1.5]\ntarget = [0.0, 0.0, 0.3]\nup = [1.0, 0.0, 0.0]\n"
                                        "start_time = 0.0015\nend_time = 0.0035\nall_frames = true\nmovie = false\n";
  REQUIRE(cli({"render", (out / "run.h5").string(), "--camera", (out / "window.toml").string(), "--out",
               (out / "window").string()}) == 0);
  int frames = 0;
  for (const auto& f : fs::directory_iterator(out / "window" / "frames" / "window")) frames += f.path().extension() == ".png";
  CHECK(frames == 2);
  // Bad input: an unknown camera key, a missing run file, a scene without cameras.
  std::ofstream(out / "bad.toml") << "[[cameras]]\nname = \"x\"\nfov_deg = 60.0\neye = [0, 0, 1]\ntarget = [0, 0, 0]\n"
                                     "up = [1, 0, 0]\nzoom = 2\n";
  CHECK(cli({"render", (out / "run.h5").string(), "--camera", (out / "bad.toml").string()}) == 2);
  CHECK(cli({"render", (out / "nothing.h5").string(), "--camera", camera.string()}) == 2);
  CHECK(cli({"render", (out / "run.h5").string()}) == 2);
}

TEST_CASE("run and restart film with the cameras of a --camera file, recorded in the run's scene, and a bad file is "
          "refused by name with nothing written",
          "[cli]") {
  const fs::path out = tempDir("film");
  fs::create_directories(out);
  std::ofstream(out / "top.toml") << "[[cameras]]\nname = \"top\"\nresolution = [160, 120]\nfov_deg = 60.0\n"
                                     "eye = [0.0, 0.0, 1.5]\ntarget = [0.0, 0.0, 0.3]\nup = [1.0, 0.0, 0.0]\n"
                                     "frame_rate = 1000.0\nstill_interval = 0.002\nmovie = false\n";
  const std::vector<std::string> base{"--quiet", "--set", "scene.end_time=0.004", "--set", "particles.0.count=100",
                                      "--camera", (out / "top.toml").string()};
  std::vector<std::string> args{"run", kScene, "--out", (out / "first").string(), "--set", "output.checkpoint=true"};
  args.insert(args.end(), base.begin(), base.end());
  REQUIRE(cli(args) == 0);
  CHECK(fs::exists(out / "first" / "top_still_000000.png"));
  CHECK(fs::exists(out / "first" / "top_still_000001.png"));
  const nlohmann::json r = nlohmann::json::parse(slurp(out / "first" / "results.json"));
  REQUIRE(r["cameras"].size() == 1);
  // The checkpoint's scene has the camera: a restart films on without --camera.
  REQUIRE(cli({"restart", (out / "first" / "checkpoint.h5").string(), "--out", (out / "second").string(), "--quiet",
               "--set", "scene.end_time=0.008"}) == 0);
  CHECK(fs::exists(out / "second" / "top_still_000001.png"));  // at 0.006 and 0.008 s: a run numbers its own
  CHECK(nlohmann::json::parse(slurp(out / "second" / "results.json"))["cameras"].size() == 1);
  // A set's run lines carry the cameras as one --set each, on one line.
  REQUIRE(cli({"sweep", kScene, "--vary", "scene.seed=1,2", "--camera", (out / "top.toml").string(), "--plan",
               (out / "plan").string()}) == 0);
  const std::string lines = slurp(out / "plan" / "runs.txt");
  CHECK(std::count(lines.begin(), lines.end(), '\n') == 2);
  CHECK_THAT(lines, Catch::Contains("--set 'cameras=[{ ") && Catch::Contains("name = '\\''top'\\''"));
  // Bad files: a key cameras do not have, a file that is not there; exit 2, no output folder.
  std::ofstream(out / "bad.toml") << "[[cameras]]\nname = \"x\"\nzoom = 2\n";
  for (const fs::path& camera : {out / "bad.toml", out / "missing.toml"}) {
    const auto [code, said] = cliStderr({"run", kScene, "--out", (out / "bad").string(), "--camera", camera.string()});
    CHECK(code == 2);
    CHECK_THAT(said, Catch::Contains("--camera") && Catch::Contains(camera.string()));
    CHECK_FALSE(fs::exists(out / "bad"));
  }
  fs::remove_all(out);
}
