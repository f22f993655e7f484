#include "sets/run_plan.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <ostream>
#include <sstream>
#include <cerrno>
#include <csignal>
#include <string_view>
#include <thread>

#include "common/atomic_file.h"
#include "common/json_text.h"
#include "sets/plan_file.h"

extern char** environ;

namespace rocklab::experiments::detail {

using json = nlohmann::json;
namespace fs = std::filesystem;

// Quoted for POSIX sh (run_plan.h): 'it'\''s'.
std::string shellQuote(const std::string& s) {
  // A word of these characters means the same to the shell bare: the line stays readable.
  const bool plain = !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("_-./=:,+@%").find(c) != std::string_view::npos;
  });
  if (plain) return s;
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

namespace {

/// key=value with characters a file name can carry; the rest become '_'.
std::string folderName(const SweepOptions& o, const std::vector<std::string>& values) {
  std::string name;
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (k) name += "__";
    for (char c : o.vary[k].first + "=" + values[k])
      name += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '=' || c == '-' || c == '+') ? c : '_';
  }
  if (name.size() > 120) {  // keep names short: a prefix and a hash of the whole
    std::ostringstream h;
    h << std::hex << std::hash<std::string>{}(name);
    name = name.substr(0, 100) + "-" + h.str();
  }
  return name;
}

/// The rocklab executable the run lines call: ROCKLAB_EXE when set (tests that
/// drive the CLI in-process set it), else this process's own executable, read once:
/// a rebuild while a set runs replaces the file, and /proc/self/exe then names the
/// old one "(deleted)"; the path itself is what later lines must call.
fs::path selfExecutable() {
  if (const char* exe = std::getenv("ROCKLAB_EXE"); exe && *exe) return fs::absolute(exe);
  static const fs::path self = [] {
    std::error_code ec;
    std::string p = fs::read_symlink("/proc/self/exe", ec).string();
    if (ec) return fs::path("rocklab");
    const std::string deleted = " (deleted)";
    if (p.size() > deleted.size() && p.compare(p.size() - deleted.size(), deleted.size(), deleted) == 0)
      p.erase(p.size() - deleted.size());
    return fs::path(p);
  }();
  return self;
}

/// What went wrong, from a run's log: its last "error..." line (the watchdog's or the
/// scene reader's message), else its last "rocklab: stopped/interrupted" line, else its
/// last line.
std::string lastError(const fs::path& log_file) {
  std::ifstream in(log_file);
  std::string line, last, error, stopped;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    last = line;
    if (line.rfind("error", 0) == 0) error = line;
    if (line.rfind("rocklab: stopped", 0) == 0 || line.rfind("rocklab: interrupted", 0) == 0) stopped = line;
  }
  return !error.empty() ? error : !stopped.empty() ? stopped : last;
}

void writeExit(const fs::path& set_dir, const std::string& name, int code) {
  writeAtomically(set_dir / "logs" / (name + ".exit"), std::to_string(code) + "\n");
}

/// An invalid run, not started: its log holds the message, its exit code is 2.
void recordInvalid(const fs::path& set_dir, const PlannedRun& run) {
  writeAtomically(set_dir / "logs" / (run.name + ".log"), "error: " + run.invalid + "\n");
  writeExit(set_dir, run.name, kExitBadInput);
}

/// One run started as a child process in a process group of its own, its stdout and
/// stderr into `log`; its pid, or -1 when it could not be started.
pid_t spawnRun(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawnattr_t attributes;
  posix_spawn_file_actions_init(&files);
  posix_spawnattr_init(&attributes);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, STDOUT_FILENO, STDERR_FILENO);
  posix_spawnattr_setpgroup(&attributes, 0);
  // The child starts with the default stop-signal handlers, not this process's.
  sigset_t defaults;
  sigemptyset(&defaults);
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&defaults, s);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF);
  pid_t pid = -1;
  if (posix_spawn(&pid, argv[0], &files, &attributes, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&files);
  posix_spawnattr_destroy(&attributes);
  return pid;
}

std::string clock(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char text[32];
  std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return text;
}

}  // namespace

int defaultJobs() { return std::max(1u, std::thread::hardware_concurrency()); }

std::vector<PlannedRun> planRuns(const SweepOptions& o) {
  std::vector<PlannedRun> runs;
  std::map<std::string, int> seen;
  for (const Variant& v : expandVariants(o)) {
    PlannedRun r;
    r.values = v.values;
    r.name = folderName(o, v.values);
    if (const int n = seen[r.name]++; n > 0) r.name += "-" + std::to_string(n + 1);
    r.overrides = o.overrides;
    bool seed_varied = false;
    for (std::size_t k = 0; k < o.vary.size(); ++k) {
      r.overrides.push_back(o.vary[k].first + "=" + v.values[k]);
      seed_varied = seed_varied || o.vary[k].first == "scene.seed";
    }
    try {
      const Scene scene = loadSetScene(o.scene, r.overrides);
      // The seed in the line: each run is reproducible alone, whatever the file says later.
      if (!seed_varied) r.overrides.push_back("scene.seed=" + std::to_string(scene.run.seed));
    } catch (const SceneError& e) {
      r.invalid = e.what();
    }
    runs.push_back(r);
  }
  return runs;
}

std::vector<std::string> runArguments(const fs::path& set_dir, const std::string& scene_path, const PlannedRun& run) {
  // A checkpoint source: each run restarts from it (`rocklab restart`), with its own --set.
  const std::string command = restartsFrom(scene_path) ? "restart" : "run";
  std::vector<std::string> args = {selfExecutable().string(), command,  scene_path,        "--out",
                                   (fs::absolute(set_dir) / "runs" / run.name).string(), "--threads",
                                   "1",          "--quiet", "--skip-complete", "--overwrite"};
  for (const std::string& s : run.overrides) {
    args.push_back("--set");
    args.push_back(s);
  }
  return args;
}

std::string runCommand(const fs::path& set_dir, const std::string& scene_path, const PlannedRun& run) {
  std::string line;
  for (const std::string& a : runArguments(set_dir, scene_path, run)) line += (line.empty() ? "" : " ") + shellQuote(a);
  const fs::path logs = fs::absolute(set_dir) / "logs";
  line += " > " + shellQuote((logs / (run.name + ".log")).string()) + " 2>&1; echo $? > " +
          shellQuote((logs / (run.name + ".exit")).string());
  return line;
}

void writePlanFiles(const fs::path& set_dir, const SweepOptions& o, const std::vector<PlannedRun>& runs,
                    const json& what) {
  fs::create_directories(set_dir / "logs");
  const fs::path dir = fs::absolute(set_dir);
  const std::string scene_path = sourcePath(o.scene).string();
  json vary = json::array();
  for (const auto& [key, values] : o.vary) vary.push_back({{"key", key}, {"values", values}});
  json list = json::array();
  std::string lines;
  std::size_t planned = 0;
  std::vector<std::string> left_out;
  for (const PlannedRun& r : runs) {
    list.push_back({{"name", r.name}, {"values", r.values}, {"overrides", r.overrides}, {"invalid", r.invalid}});
    if (!r.invalid.empty()) {
      recordInvalid(dir, r);
      left_out.push_back(r.name);
      continue;
    }
    lines += runCommand(dir, scene_path, r) + "\n";
    ++planned;
  }
  json plan = what;
  plan["scene"] = scene_path;
  plan["overrides"] = o.overrides;
  plan["vary"] = vary;
  plan["runs"] = list;
  writeAtomically(dir / "plan.json", jsonText(plan));
  writeAtomically(dir / "runs.txt", lines);

  std::ostringstream sb;
  sb << "#!/bin/bash\n"
     << "# One Slurm array task per line of runs.txt (each run: one process, one thread).\n"
     << "# Submit: sbatch " << (dir / "slurm.sbatch").string() << "; then: rocklab collect " << dir.string() << "\n"
     << "#SBATCH --job-name=rocklab-" << sourceName(scene_path) << "\n"
     << "#SBATCH --array=1-" << planned << "\n"
     << "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n"
     << "#SBATCH --mem=" << o.slurm.memory << "\n"
     << "#SBATCH --time=" << o.slurm.time << "\n";
  if (!o.slurm.partition.empty()) sb << "#SBATCH --partition=" << o.slurm.partition << "\n";
  sb << "#SBATCH --output=" << (dir / "logs" / "slurm-%A_%a.out").string() << "\n"
     << "export OMP_NUM_THREADS=1\n"
     << "line=$(sed -n \"${SLURM_ARRAY_TASK_ID}p\" " << shellQuote((dir / "runs.txt").string()) << ")\n"
     << "exec /bin/sh -c \"$line\"\n";
  writeAtomically(dir / "slurm.sbatch", sb.str());

  std::ostringstream rd;
  rd << "# " << what.value("kind", std::string("set")) << " of " << sourceName(scene_path) << ": " << planned
     << " independent runs\n\n";
  if (!left_out.empty()) {
    rd << "Left out, their settings invalid (the message is in `logs/NAME.log`; `plan.json` keeps them):";
    for (const std::string& name : left_out) rd << " `" << name << "`";
    rd << ".\n\n";
  }
  rd
     << "Each line of `runs.txt` is one run: "
     << (restartsFrom(scene_path) ? "`rocklab restart` from " + scene_path : std::string("`rocklab run`"))
     << " with its own `--out` folder under `runs/`, every\n"
     << "`--set` it needs (the seed included), one thread, its log and exit code under `logs/`. A line\n"
     << "whose run already completed does nothing (`--skip-complete`), so running the list again, or\n"
     << "after deleting one run folder, redoes only what is missing (an unfinished attempt's files are\n"
     << "removed first: `--overwrite`).\n\n"
     << "Run the list on this machine with GNU parallel (one run per core):\n\n"
     << "    parallel --jobs " << defaultJobs() << " < " << (dir / "runs.txt").string() << "\n\n"
     << "or on a Slurm cluster as an array job (one task per line; resources in the header):\n\n"
     << "    sbatch " << (dir / "slurm.sbatch").string() << "\n\n"
     << "then merge the finished runs into the table, plot and recommendation:\n\n"
     << "    rocklab collect " << dir.string() << "\n";
  writeAtomically(dir / "README.md", rd.str());
}

int reportPlan(const fs::path& set_dir, const std::vector<PlannedRun>& runs, const std::string& kind,
               std::ostream& log) {
  int code = kExitOk;
  for (const PlannedRun& r : runs) {
    if (r.invalid.empty()) continue;
    log << "  " << r.name << ": invalid, left out of the run list: " << r.invalid << "\n";
    code = kExitBadInput;
  }
  log << kind << ": planned, nothing run: " << (set_dir / "runs.txt").string() << " (see "
      << (set_dir / "README.md").string() << "); afterwards: rocklab collect " << set_dir.string() << "\n";
  return code;
}

std::vector<Variant> inspectRuns(const fs::path& set_dir, const std::vector<PlannedRun>& runs) {
  std::vector<Variant> out;
  for (const PlannedRun& run : runs) {
    Variant& v = out.emplace_back();
    v.values = run.values;
    const fs::path results = set_dir / "runs" / run.name / "results.json";
    // A stopped run's results (watchdog, Ctrl-C) still tell something.
    v.results = readJsonFile(results);
    if (v.results.is_discarded()) v.results = nullptr;
    if (resultStatus(v.results) == "completed") {
      v.code = kExitOk;
      v.status = "ok";
      continue;
    }
    int code = kMissing;
    if (std::ifstream ex{set_dir / "logs" / (run.name + ".exit")}; ex) ex >> code;
    if (code == kExitOk) code = 1;  // exited 0 without a complete results.json: not a success
    v.code = code;
    if (code == kMissing) {
      v.status = "missing";
      continue;
    }
    const std::string error = lastError(set_dir / "logs" / (run.name + ".log"));
    std::string e = error.rfind("error: ", 0) == 0 ? error.substr(7) : error;
    e = e.substr(0, 160);
    std::replace(e.begin(), e.end(), ',', ';');  // the table is CSV
    v.status = "exit " + std::to_string(code) + (e.empty() ? "" : ": " + e);
  }
  return out;
}

int executeRuns(const fs::path& set_dir, const SweepOptions& o, const std::vector<PlannedRun>& runs, std::ostream& log) {
  fs::create_directories(set_dir / "logs");
  std::vector<const PlannedRun*> todo;
  std::size_t skipped = 0;
  for (const PlannedRun& r : runs) {
    if (runCompleted(set_dir / "runs" / r.name)) {
      ++skipped;
    } else if (!r.invalid.empty()) {
      recordInvalid(set_dir, r);
      log << "  " << r.name << ": invalid, not run: " << r.invalid << "\n";
    } else {
      todo.push_back(&r);
    }
  }
  if (skipped) log << "  " << skipped << " of " << runs.size() << " runs already complete: not run again\n";
  const int jobs = o.jobs < 0 ? defaultJobs() : o.jobs;
  const auto t0 = std::chrono::steady_clock::now();
  std::size_t done = 0, failed = 0;
  auto finished = [&](const PlannedRun& r, int code) {
    ++done;
    if (code != kExitOk) ++failed;
    log << "  " << r.name << " -> " << (code == kExitOk ? "done" : "exit " + std::to_string(code)) << "\n";
  };

  if (jobs == 0) {  // in this process, one after the other, all threads each
    for (const PlannedRun* r : todo) {
      Scene scene = loadSetScene(o.scene, r->overrides);
      // Replace: what an interrupted attempt left (a complete run is skipped above).
      const RunOptions ro = setRunOptions(o, set_dir / "runs" / r->name);
      int code;
      {
        std::ofstream run_log(set_dir / "logs" / (r->name + ".log"));
        code = runScene(std::move(scene), ro, run_log);
      }
      writeExit(set_dir, r->name, code);
      finished(*r, code);
      if (code == kExitInterrupted) return kExitInterrupted;
    }
    return kExitOk;
  }

  // A pool of `jobs` processes, each one run of one thread: the lines of runs.txt.
  const std::string scene_path = sourcePath(o.scene).string();
  std::map<pid_t, const PlannedRun*> running;
  std::size_t next = 0;
  auto last_line = std::chrono::steady_clock::now();
  auto progress = [&] {
    if (!o.progress) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::size_t left = todo.size() - done;
    std::ostringstream line;
    line << "runs: " << done << "/" << todo.size() << " done, " << failed << " failed, " << running.size()
         << " running, " << jobs << " processes x 1 thread, elapsed " << clock(elapsed);
    // Runs finish at the pool's pace: elapsed / done already counts the parallelism.
    if (done > 0) line << ", ETA " << clock(elapsed / static_cast<double>(done) * static_cast<double>(left));
    log << line.str() << "\n";
  };
  bool forwarded = false;
  while (next < todo.size() || !running.empty()) {
    while (!stopRequested() && next < todo.size() && static_cast<int>(running.size()) < jobs) {
      const PlannedRun* r = todo[next++];
      const pid_t pid = spawnRun(runArguments(set_dir, scene_path, *r), set_dir / "logs" / (r->name + ".log"));
      if (pid <= 0) {
        writeExit(set_dir, r->name, 1);
        finished(*r, 1);
        continue;
      }
      running[pid] = r;
    }
    // Each run is its own process group (spawnRun), out of reach of a signal sent to
    // this one: Ctrl-C, SIGTERM or SIGHUP here is passed on once, as SIGTERM, so every
    // run stops cleanly (checkpoint, results.json "interrupted") before the set ends.
    if (stopRequested() && !forwarded) {
      for (const auto& [child, run] : running) ::kill(child, SIGTERM);
      forwarded = true;
    }
    if (running.empty()) break;
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid == 0) {  // none finished: a progress line every 30 s, so long runs are seen to go on
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      if (std::chrono::steady_clock::now() - last_line > std::chrono::seconds(30)) {
        progress();
        last_line = std::chrono::steady_clock::now();
      }
      continue;
    }
    if (pid < 0) {
      if (errno == EINTR) continue;  // a stop signal: passed on above; wait for the runs
      break;
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const PlannedRun* r = it->second;
    running.erase(it);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    writeExit(set_dir, r->name, code);
    finished(*r, code);
    progress();
    last_line = std::chrono::steady_clock::now();
  }
  return stopRequested() ? kExitInterrupted : kExitOk;
}

}  // namespace rocklab::experiments::detail
