#pragma once
// The `rocklab agglomerate` subcommand's options (CLI11), bound to AgglomerateOptions.
#include "agglomerate/agglomerate_command.h"

namespace CLI {
class App;
}

namespace rocklab::experiments {

/// Adds the subcommand "agglomerate" to `app`; --no-preview sets `no_preview`.
void addAgglomerateCommand(CLI::App& app, AgglomerateOptions& options, bool& no_preview);

}  // namespace rocklab::experiments
