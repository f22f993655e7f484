// The CLI on hostile input and in hostile conditions: no path ends in std::terminate
// (every command names the file and exits with its documented code), an earlier run
// is never mixed with a new one, SIGTERM and SIGHUP stop a run like Ctrl-C, and
// `rocklab shape` says when it missed what was asked.
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "cli_support.h"
#include "rocklab/sim/output/checkpoint.h"

namespace fs = std::filesystem;
using Catch::Contains;
using nlohmann::json;
using rocklab::experiments::test::cli;
using rocklab::experiments::test::slurp;
using rocklab::experiments::test::waitUntilRunning;

namespace {

fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rocklab-harden-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}
const std::string kHopper = std::string(ROCKLAB_SOURCE_DIR) + "/assets/scenes/hopper.toml";
const std::vector<std::string> kShort = {"--quiet", "--threads", "1", "--set", "particles.0.count=100", "--set",
                                         "scene.end_time=0.001", "--set", "output.vtk=true", "--set",
                                         "output.frame_interval=0.0005"};

/// The exit code and what the command wrote on stderr.
struct Outcome {
  int code;
  std::string err;
};
Outcome run(std::vector<std::string> args) {
  std::ostringstream err;
  auto* const old = std::cerr.rdbuf(err.rdbuf());
  const int code = cli(std::move(args));
  std::cerr.rdbuf(old);
  return {code, err.str()};
}
std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

/// Every entry of a folder with its size, to tell "nothing touched".
std::string listing(const fs::path& dir) {
  std::ostringstream s;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    s << e.path().string() << " " << (e.is_regular_file() ? fs::file_size(e.path()) : 0) << " "
      << e.last_write_time().time_since_epoch().count() << "\n";
  return s.str();
}

}  // namespace

TEST_CASE("no input ends in std::terminate: each command names the file and exits with its code", "[cli]") {
  const fs::path dir = tempDir("terminate");
  fs::create_directories(dir);

  // A lattice that passes the per-axis range but not the ball cap: refused with its memory.
  std::ofstream(dir / "lattice.toml") << "extends = \"" << kHopper << "\"\n[[particles]]\ntype = \"lattice\"\n"
                                          "material = \"pebble\"\nradius = 0.001\ncell = 0.002\n"
                                          "counts = [10000, 10000, 10000]\n";
  Outcome o = run({"check", (dir / "lattice.toml").string()});
  CHECK(o.code == 2);
  CHECK_THAT(o.err, Contains("particles.0.counts") && Contains("GB of memory"));

  // A PLY whose header under-states its vertex count (assimp aborts on it): shape and a mesh wall.
  const fs::path ply = dir / "under.ply";
  std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
                        "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  o = run({"shape", ply.string(), "--out", (dir / "shape").string(), "--no-preview"});
  CHECK(o.code == 2);
  CHECK_THAT(o.err, Contains(ply.string()) && Contains("under-state"));
  CHECK_FALSE(fs::exists(dir / "shape"));
  std::ofstream(dir / "wall.toml") << "extends = \"" << kHopper << "\"\n[[walls]]\ntype = \"mesh\"\nmaterial = \"steel\"\nfile = \"under.ply\"\n";
  o = run({"check", (dir / "wall.toml").string()});
  CHECK(o.code == 2);
  CHECK_THAT(o.err, Contains("key 'walls.0.file' = \"under.ply\"") && Contains("under-state"));

  // collect on damaged sets: a results.json whose status is a number, a folder named
  // results.json, a plan with empty metrics or values.
  const fs::path set = dir / "set";
  REQUIRE(cli({"sweep", kHopper, "--vary", "contact.damping_normal=0.1,0.2", "--plan", set.string(), "--set",
               "particles.0.count=50", "--set", "scene.end_time=0.0005"}) == 0);
  const json plan = json::parse(slurp(set / "plan.json"));
  const std::string run0 = plan["runs"][0]["name"], run1 = plan["runs"][1]["name"];
  fs::create_directories(set / "runs" / run0);
  std::ofstream(set / "runs" / run0 / "results.json") << "{\"status\": 5}";
  fs::create_directories(set / "runs" / run1 / "results.json");
  o = run({"collect", set.string()});
  CHECK(o.code == 4);  // finished, but no run is complete
  CHECK_THAT(o.err, Contains("0 complete"));
  for (const auto& [key, empty] : {std::pair<std::string, json>{"metrics", json::array()},
                                   {"vary", json::array({{{"key", "contact.damping_normal"}, {"values", json::array()}}})}}) {
    json damaged = plan;
    damaged[key] = empty;
    std::ofstream(set / "plan.json") << damaged.dump();
    o = run({"collect", set.string()});
    CHECK(o.code == 2);
    CHECK_THAT(o.err, Contains((set / "plan.json").string()) && Contains("key '" + key));
  }

  // A scene in a folder whose name is not UTF-8: the clump file's path goes into
  // results.json (clump_shapes), which stays valid JSON.
  const fs::path latin1 = dir / std::string("sc\xe8ne\xff");
  fs::create_directories(latin1);
  std::ofstream(latin1 / "c.txt") << "0 0 0 0.005\n0.004 0 0 0.005\n";
  std::ofstream(latin1 / "clumps.toml") << "extends = \"" << kHopper << "\"\n[[particles]]\ntype = \"random\"\n"
                                           "material = \"pebble\"\nshape = \"file\"\nfile = \"c.txt\"\ncount = 20\n"
                                           "region_min = [-0.145, -0.045, 0.32]\nregion_max = [0.145, 0.045, 0.65]\n";
  o = run(with({"run", (latin1 / "clumps.toml").string(), "--out", (latin1 / "out").string()}, kShort));
  CHECK(o.code == 0);
  const json results = json::parse(slurp(latin1 / "out" / "results.json"));
  CHECK_THAT(results["clump_shapes"][0]["shape"].get<std::string>(), Contains("c.txt"));
  fs::remove_all(dir);
}

TEST_CASE("an output folder the run cannot write into is refused before the run", "[cli]") {
  // As root the permission bits do not bind: the run is made in a child that gives up root.
  const fs::path dir = tempDir("readonly");
  fs::create_directories(dir / "out");
  // The child, no longer root, must still read the scene wherever the source tree
  // is (a clone in a 0700 mktemp folder): it runs a readable copy.
  const fs::path scene = dir / "hopper.toml";
  fs::copy_file(kHopper, scene);
  fs::permissions(scene, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read | fs::perms::others_read);
  fs::permissions(dir, fs::perms::owner_all | fs::perms::group_exec | fs::perms::others_exec);
  fs::permissions(dir / "out", fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                   fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) ::_exit(50);
    std::ostringstream err;
    std::cerr.rdbuf(err.rdbuf());
    const int code = cli(with({"run", scene.string(), "--out", (dir / "out").string()}, kShort));
    ::_exit(code == 2 && err.str().find("cannot write into output folder") != std::string::npos ? 0 : 40 + code);
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);  // 2 with the message, not 134 (abort)
  CHECK(fs::is_empty(dir / "out"));
  fs::permissions(dir / "out", fs::perms::owner_all);
  fs::remove_all(dir);
}

TEST_CASE("an earlier run in --out is refused without --overwrite and cleared with it", "[cli]") {
  const fs::path out = tempDir("earlier");
  REQUIRE(run(with({"run", kHopper, "--out", out.string()}, kShort)).code == 0);
  // A frame and a still of a longer earlier run, and a file of the user's.
  std::ofstream(out / "vtk" / "particles_000099.vtp") << "stale";
  std::ofstream(out / "side_still_000009.png") << "stale";
  std::ofstream(out / "notes.txt") << "mine";
  const std::string before = listing(out);

  // Refused: exit 2, every file as it was.
  for (const char* command : {"run", "restart"}) {
    INFO(command);
    const Outcome o = std::string(command) == "run"
                          ? run(with({command, kHopper, "--out", out.string()}, kShort))
                          : run({command, (out / "checkpoint.h5").string(), "--out", out.string(), "--quiet"});
    CHECK(o.code == 2);
    CHECK_THAT(o.err, Contains("holds an earlier run") && Contains("--overwrite"));
    CHECK(listing(out) == before);
  }
  // With --overwrite: the old run's files are gone before the new one writes.
  Outcome o = run(with({"run", kHopper, "--out", out.string(), "--overwrite"}, kShort));
  CHECK(o.code == 0);
  CHECK_FALSE(fs::exists(out / "vtk" / "particles_000099.vtp"));
  CHECK_FALSE(fs::exists(out / "side_still_000009.png"));
  CHECK(slurp(out / "notes.txt") == "mine");
  CHECK(json::parse(slurp(out / "results.json"))["simulated_time_s"].get<double>() == Approx(0.001).margin(1e-5));
  // A restart into its own folder: the checkpoint is read before the folder is cleared.
  o = run({"restart", (out / "checkpoint.h5").string(), "--out", out.string(), "--overwrite", "--quiet", "--set",
           "scene.end_time=0.0015"});
  CHECK(o.code == 0);
  const json r = json::parse(slurp(out / "results.json"));
  CHECK(r["status"] == "completed");
  CHECK(r["simulated_time_s"].get<double>() == Approx(0.0015).margin(1e-5));
  CHECK(rocklab::sim::output::readCheckpoint(out / "checkpoint.h5").state.step == r["steps"].get<std::uint64_t>());
  // ...and the checkpoint it continues from is kept until the run writes its own: a
  // continuation that writes none (or is stopped first) leaves the way back intact.
  const std::string kept = slurp(out / "checkpoint.h5");
  o = run({"restart", (out / "checkpoint.h5").string(), "--out", out.string(), "--overwrite", "--quiet", "--set",
           "scene.end_time=0.002", "--set", "output.checkpoint=false"});
  CHECK(o.code == 0);
  CHECK(json::parse(slurp(out / "results.json"))["simulated_time_s"].get<double>() == Approx(0.002).margin(1e-5));
  REQUIRE(fs::exists(out / "checkpoint.h5"));
  CHECK(slurp(out / "checkpoint.h5") == kept);
  fs::remove_all(out);
}

TEST_CASE("a completed run is skipped by --skip-complete before its scene is even read", "[cli]") {
  const fs::path out = tempDir("skip");
  REQUIRE(run(with({"run", kHopper, "--out", out.string()}, kShort)).code == 0);
  const std::string before = listing(out);
  // The key would be refused if the scene were loaded: the run is skipped first (a
  // batch re-run does not rebuild a dense agglomerate for every finished run).
  const Outcome o = run(with({"run", kHopper, "--out", out.string(), "--skip-complete", "--set", "scene.no_such_key=1"}, kShort));
  CHECK(o.code == 0);
  CHECK_THAT(o.err, Contains("is complete; not run again"));
  CHECK(listing(out) == before);
  // A folder without a completed results.json is run (here: refused for the bad key).
  fs::remove(out / "results.json");
  CHECK(run(with({"run", kHopper, "--out", out.string(), "--skip-complete", "--set", "scene.no_such_key=1"}, kShort)).code == 2);
  fs::remove_all(out);
}

TEST_CASE("SIGTERM and SIGHUP stop a run like Ctrl-C and a second signal kills", "[cli]") {
  for (const int signal : {SIGTERM, SIGHUP}) {
    INFO("signal " << signal);
    const fs::path out = tempDir("signal" + std::to_string(signal));
    const auto before = std::signal(signal, SIG_DFL);  // the test runner's own handler
    std::signal(signal, before);
    std::thread sender([signal, &out] {
      waitUntilRunning(out);
      std::raise(signal);  // what Slurm sends at its time limit, or a closed terminal
    });
    const int code = cli({"run", kHopper, "--out", out.string(), "--quiet", "--set", "scene.end_time=100"});
    sender.join();
    CHECK(code == 130);
    const json r = json::parse(slurp(out / "results.json"));
    CHECK(r["status"] == "interrupted");
    const auto cp = rocklab::sim::output::readCheckpoint(out / "checkpoint.h5");
    CHECK(cp.state.step == r["steps"].get<std::uint64_t>());
    CHECK(std::signal(signal, before) == before);  // the handler before the command is back
    fs::remove_all(out);

    // The second signal ends the process at once (in a child: the test's own would die).
    const fs::path out2 = tempDir("signal2-" + std::to_string(signal));
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      std::thread twice([signal, &out2] {
        waitUntilRunning(out2);
        std::raise(signal);
        std::raise(signal);
      });
      const int c = cli({"run", kHopper, "--out", out2.string(), "--quiet", "--threads", "1", "--set",
                         "scene.end_time=100"});
      twice.join();
      ::_exit(c == 130 ? 40 : 41);
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    CHECK((WIFSIGNALED(status) && WTERMSIG(status) == signal));
    fs::remove_all(out2);
  }
}

TEST_CASE("a run started with SIGHUP ignored (nohup) outlives a hang-up", "[cli]") {
  const fs::path out = tempDir("nohup");
  const auto before = std::signal(SIGHUP, SIG_IGN);  // as nohup starts it
  std::thread sender([&out] {
    waitUntilRunning(out);
    std::raise(SIGHUP);  // the terminal closing
  });
  const int code = cli({"run", kHopper, "--out", out.string(), "--quiet", "--set", "scene.end_time=0.05"});
  sender.join();
  CHECK(std::signal(SIGHUP, before) == SIG_IGN);  // still ignored after the command
  CHECK(code == 0);
  CHECK(json::parse(slurp(out / "results.json"))["status"] != "interrupted");
  fs::remove_all(out);
}

TEST_CASE("a tool that misses what was asked says why and exits 1", "[cli][shape]") {
  // calibrate: a target outside the values tried has no estimate.
  const fs::path cal = tempDir("calibrate");
  Outcome c = run({"calibrate", "drop", "--vary", "contact.damping_normal=0.3,0.4", "--target", "restitution=0.72",
                   "--quiet", "--out", cal.string()});
  CHECK(c.code == 1);
  CHECK_THAT(c.err, Contains("no estimate: the target is not between any two neighbouring values"));
  CHECK(json::parse(slurp(cal / "calibration.json"))["status"] == "no_estimate");
  fs::remove_all(cal);

  const fs::path dir = tempDir("shape");
  fs::create_directories(dir);
  const std::string mesh = (dir / "p.stl").string();
  auto shape = [&](const std::string& out, std::vector<std::string> more) {
    return run(with({"shape", mesh, "--generate", "pebble", "--unit", "mm", "--size", "0.02", "--no-preview", "--out",
                     (dir / out).string()},
                    more));
  };
  // --tolerance: the stop test is the true uncovered fraction, so a clump stopped on it is within it.
  Outcome o = shape("tol", {"--tolerance", "0.05", "--spheres", "200"});
  REQUIRE(o.code == 0);
  json r = json::parse(slurp(dir / "tol" / "results.json"));
  CHECK(r["status"] == "done");
  CHECK_THAT(r["stop_reason"].get<std::string>(), Contains("tolerance reached"));
  CHECK(r["uncovered_volume_fraction"].get<double>() <= 0.05);
  CHECK(r["volume_error"].get<double>() >= -0.05);  // the true error, measured apart
  // Too few spheres for the tolerance: written, but exit 1 and said why.
  o = shape("few", {"--tolerance", "0.01", "--spheres", "3"});
  CHECK(o.code == 1);
  r = json::parse(slurp(dir / "few" / "results.json"));
  CHECK(r["status"] == "target_not_met");
  CHECK_THAT(r["message"].get<std::string>(), Contains("--tolerance 0.01 not reached") && Contains("sphere count reached"));
  CHECK_THAT(o.err, Contains("--tolerance 0.01 not reached"));
  // Candidates run out below --spheres (large spheres only): exit 1, the reason named.
  o = shape("out", {"--spheres", "200", "--min-radius", "0.3"});
  CHECK(o.code == 1);
  r = json::parse(slurp(dir / "out" / "results.json"));
  CHECK(r["status"] == "target_not_met");
  CHECK_THAT(r["stop_reason"].get<std::string>(), Contains("no candidate sphere adds volume"));
  CHECK(r["sphere_count"].get<int>() < 200);
  // A scan in metres read as mm: under 1 mm across, warned.
  o = run({"shape", mesh, "--generate", "pebble", "--unit", "m", "--size", "0.02", "--no-preview", "--spheres", "2",
           "--out", (dir / "m").string()});
  REQUIRE(o.code == 0);
  o = run({"shape", mesh, "--unit", "mm", "--no-preview", "--spheres", "2", "--out", (dir / "mm").string()});
  CHECK_THAT(o.err, Contains("probably in metres"));
  fs::remove_all(dir);
}
