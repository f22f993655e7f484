#pragma once
// The source's git commit, taken when CMake configured the build (a commit made
// after that shows only after cmake runs again); "" when it was not a git checkout.
namespace rocklab::experiments::detail {
const char* sourceCommit();
}  // namespace rocklab::experiments::detail
