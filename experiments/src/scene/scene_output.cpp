// Scene reader: [scene] (what the run is called and how long it lasts) and
// [output] (what it writes).
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

std::string folderNameProblem(const std::string& name) {
  if (name.empty()) return "must not be empty";
  if (name == "." || name == "..") return "is not a name ('.' and '..' are folders)";
  if (name.find_first_of("/\\") != std::string::npos)
    return "is a name, not a path: no '/' or '\\' (it names an output folder or file)";
  for (const char c : name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "must not hold control characters";
  if (name.size() > 100) return "must be at most 100 characters (it names an output folder or file)";
  return "";
}

/// [scene]: name, description, seed and the end (end_time or steps).
void readRunTable(TableReader& root, RunSettings& run) {
  auto t = root.table("scene");
  if (!t)
    root.fail("scene",
              "missing; a [scene] table with name and end_time (or "
              "steps) is required");
  run.name = t->requiredString("name");
  if (const std::string problem = folderNameProblem(run.name); !problem.empty()) t->fail("name", problem);
  run.description = t->string("description", "");
  run.seed = static_cast<std::uint64_t>(t->integer("seed", 1, Range::nonNegative()));
  run.end_time = t->number("end_time", 0.0, Range::nonNegative());
  run.steps = static_cast<std::uint64_t>(t->integer("steps", 0, Range::nonNegative()));
  if ((run.end_time > 0) == (run.steps > 0))
    t->fail(t->has("steps") ? "steps" : "end_time",
            "give exactly one of end_time (s, > 0) and steps (> 0)");
  t->finish();
}

/// [output]: what the run writes and how often.
void readOutput(TableReader& root, RunSettings& r) {
  if (auto t = root.table("output")) {
    r.frame_interval = t->number("frame_interval", 0.0, Range::nonNegative());
    r.energy_interval = t->number("energy_interval", 0.0, Range::nonNegative());
    r.checkpoint_interval = t->number("checkpoint_interval", 0.0, Range::nonNegative());
    r.hdf5 = t->boolean("hdf5", r.hdf5);
    r.vtk = t->boolean("vtk", r.vtk);
    r.checkpoint = t->boolean("checkpoint", r.checkpoint);
    t->finish();
  }
}

}  // namespace rocklab::experiments::detail
