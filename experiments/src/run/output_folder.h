#pragma once
// The output folder of a run made ready before anything is written into it: an
// earlier run there is refused or cleared (RunOptions::earlier_run), so two runs'
// files never sit side by side (a restart would otherwise continue the wrong one),
// and a folder the run cannot write into is refused before the run starts.
#include <iosfwd>

#include "rocklab/experiments/run.h"

namespace rocklab::experiments::detail {

/// kExitOk, or kExitBadInput with the reason on `log` (nothing touched when refused).
int prepareOutputFolder(const RunOptions& options, std::ostream& log);

}  // namespace rocklab::experiments::detail
