#pragma once
// `rocklab whiten RUN_DIR`: Whiten's classification-breakage model (§h.2) as a
// calculator on a finished crusher run: the run's feed (results.json
// crusher.feed_psd and feed_mass_kg) through the model with the k1, k2, exponent
// and split asked for, printed beside the DEM's product and the run's own
// from-parameters curve, and written as whiten.json and whiten.png (docs/crusher.md).
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>

namespace rocklab::experiments {

struct WhitenCommandOptions {
  std::filesystem::path run_dir;
  std::optional<double> k1_mm, k2_mm;  // default: the run's (crusher.whiten.from_parameters)
  double exponent = 2.0;
  std::string mode;                    // "triple" | "equal"; "" = the run's
  std::filesystem::path out_dir;       // "" = run_dir
};

/// Exit code: 0, or 2 (no such run, not a crusher run, bad values; nothing written)
/// with the message on err naming the file and key.
int runWhitenCommand(const WhitenCommandOptions& options, std::ostream& out, std::ostream& err);

}  // namespace rocklab::experiments
