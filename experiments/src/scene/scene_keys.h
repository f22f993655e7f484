#pragma once
// The scene reference (rocklab scene-keys, docs/scene-format.md): one line of
// documentation per scene key (scene_keys.cpp), joined with what the readers
// themselves record when they read a key (TableReader: kind, allowed values,
// default), over a corpus of scenes that reaches every reader branch (the
// built-in scenes and the coverage scenes of scene_keys.cpp). A key a reader
// reads without a documentation line, or a line no reader reads, is a problem
// and the command fails (ctest "scene-keys").
#include <string>
#include <vector>

namespace rocklab::experiments {

/// One line of the scene reference. `table` is the documentation table the
/// reader records ("" for the top level, "materials.NAME", "walls",
/// "walls.motion", "experiment.chute"); `key` "" documents the table itself.
struct KeyDoc {
  const char* table;
  const char* key;
  const char* unit;  // SI unit, "" for none
  const char* text;  // what the key does, one line
  // Replace what the reader records, where it depends on the scene: the allowed
  // values (names of the scene's own walls, cameras, materials) and the default
  // (computed from other keys).
  const char* values = nullptr;
  const char* fallback = nullptr;
};

/// Every documented table and key, in the order of the reference.
const std::vector<KeyDoc>& sceneKeyDocs();

/// The SI unit of a --set/--vary key path ("walls.top.corner.2" -> "m",
/// "particles.0.member_radius" -> "m", "scene.seed" -> ""): the documented key of
/// that name in a table of the path's first part; "" when none is documented or
/// the tables that have the name disagree. For axis labels.
std::string sceneKeyUnit(const std::string& path);
/// "PATH (UNIT)", or PATH when it has no unit.
std::string withSceneKeyUnit(const std::string& path);

/// Loads the corpus with key recording on and returns the reference as
/// Markdown; every problem (undocumented key, documented key never read,
/// default that differs between scenes) is appended to `problems`.
std::string sceneKeysMarkdown(std::vector<std::string>& problems);

}  // namespace rocklab::experiments
