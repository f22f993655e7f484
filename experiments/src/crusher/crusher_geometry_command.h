#pragma once
// `rocklab crusher-geometry SCENE`: every derived quantity of the scene's cone
// crusher ([crusher], geometry/cone_crusher.h) printed with units, the closed-side
// vertical section drawn as section.png with the gaps labelled, and results.json
// beside it (docs/crusher.md).
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

namespace rocklab::experiments {

struct CrusherGeometryOptions {
  std::string scene;                   // file or built-in name
  std::vector<std::string> overrides;  // --set
  std::filesystem::path out_dir;       // "" = out/<scene name>-geometry
};

/// Exit code: 0, or 2 (bad scene, no [crusher], cannot write) with the message on err.
int runCrusherGeometry(const CrusherGeometryOptions& options, std::ostream& out, std::ostream& err);

}  // namespace rocklab::experiments
