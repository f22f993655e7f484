// The output folder of a run made ready (output_folder.h).
#include "run/output_folder.h"

#include "common/joined_text.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ostream>
#include <string>
#include <vector>

namespace rocklab::experiments::detail {

namespace fs = std::filesystem;

namespace {

// What every run leaves (finished, stopped or killed): its marks in a folder.
constexpr const char* kRunMarks[] = {"results.json", "run.h5", "run.h5.partial", "checkpoint.h5",
                                     "checkpoint.h5.tmp", "vtk"};

/// The marks of an earlier run that `dir` holds.
std::vector<std::string> earlierRunMarks(const fs::path& dir) {
  std::vector<std::string> marks;
  std::error_code ec;
  for (const char* mark : kRunMarks)
    if (fs::exists(fs::symlink_status(dir / mark, ec))) marks.emplace_back(mark);
  return marks;
}

/// Whether `entry` is something a run writes: its marks, the cameras' frames/, and
/// the kinds of file runs write (stills and plots with their SVG, movies, tables, JSON
/// reports, report.html, files half-written when it stopped). Anything else (a scene, a clump or mesh
/// file, a log, an agglomerate library) is the user's and stays.
bool runOutput(const fs::path& entry) {
  const std::string name = entry.filename().string();
  if (std::find(std::begin(kRunMarks), std::end(kRunMarks), name) != std::end(kRunMarks) || name == "frames" ||
      name == "report.html")
    return true;
  const std::string ext = entry.extension().string();
  for (const char* e : {".png", ".svg", ".mp4", ".avi", ".csv", ".json", ".partial", ".tmp"})
    if (ext == e) return true;
  return false;
}

/// True when `entry` is the file `keep` names ("" keeps nothing).
bool sameFile(const fs::path& entry, const fs::path& keep) {
  std::error_code ec;
  return !keep.empty() && fs::equivalent(entry, keep, ec);
}

/// Removes the earlier run's outputs from `dir` but `keep` (the checkpoint a restart
/// continues from: until the continued run writes its own, it is the only way back to
/// that state, so a run stopped early loses nothing); "" or what failed.
std::string clearEarlierRun(const fs::path& dir, const fs::path& keep) {
  std::error_code ec;
  std::vector<fs::path> outputs;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec))
    if (runOutput(e.path()) && !sameFile(e.path(), keep)) outputs.push_back(e.path());
  if (ec) return "cannot list " + dir.string() + ": " + ec.message();
  for (const fs::path& p : outputs) {
    fs::remove_all(p, ec);
    if (ec) return "cannot remove " + p.string() + ": " + ec.message();
  }
  return "";
}

/// "" when this process may create files in `dir`, else why not.
std::string notWritable(const fs::path& dir) {
  if (::access(dir.c_str(), W_OK | X_OK) == 0) return "";
  return std::strerror(errno);
}

}  // namespace

int prepareOutputFolder(const RunOptions& options, std::ostream& log) {
  const fs::path& dir = options.out_dir;
  const std::string where = "output folder " + dir.string();
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (fs::exists(status)) {
    if (!fs::is_directory(status)) {
      log << "error: " << where << " exists and is not a folder; give another --out\n";
      return kExitBadInput;
    }
    if (const std::string why = notWritable(dir); !why.empty()) {
      log << "error: cannot write into " << where << ": " << why << "; give another --out\n";
      return kExitBadInput;
    }
    const std::vector<std::string> marks = earlierRunMarks(dir);
    if (!marks.empty() && options.earlier_run == EarlierRun::Refuse) {
      log << "error: " << where << " holds an earlier run (" << joinedText(marks)
          << "); give --overwrite to replace it (its files are removed first), or another --out\n";
      return kExitBadInput;
    }
    if (!marks.empty() && options.earlier_run == EarlierRun::Replace) {
      if (const std::string why = clearEarlierRun(dir, options.restart); !why.empty()) {
        log << "error: cannot clear the earlier run in " << where << ": " << why << "\n";
        return kExitBadInput;
      }
      log << "rocklab: " << where << ": the earlier run (" << joinedText(marks) << ") removed (--overwrite)"
          << (sameFile(dir / "checkpoint.h5", options.restart) ? ", but the checkpoint this run continues from\n" : "\n");
    }
  }
  fs::create_directories(dir, ec);
  if (ec) {
    log << "error: cannot create " << where << ": " << ec.message() << "\n";
    return kExitBadInput;
  }
  if (const std::string why = notWritable(dir); !why.empty()) {
    log << "error: cannot write into " << where << ": " << why << "; give another --out\n";
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace rocklab::experiments::detail
