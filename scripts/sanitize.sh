#!/usr/bin/env bash
# The whole CI suite under AddressSanitizer + UndefinedBehaviorSanitizer:
# configures the clang preset asan-clang (build-asan/), builds everything and
# runs ctest -LE validation there. Any sanitizer report fails its test (UBSan
# halts on the first error; leaks are reported by LeakSanitizer except inside
# the GL libraries, scripts/sanitizer-suppressions.txt).
#   scripts/sanitize.sh [-jN]        (default -j2; run it with nice on a shared machine)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=${1:--j2}
cd "$root"
[[ -f build-asan/CMakeCache.txt ]] || cmake --preset asan-clang
cmake --build build-asan "$jobs"
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export LSAN_OPTIONS=suppressions=$root/scripts/sanitizer-suppressions.txt:print_suppressions=0
# The sanitized build runs several times slower: a longer per-test limit.
ctest --test-dir build-asan -LE validation "$jobs" --timeout 3000 --output-on-failure
