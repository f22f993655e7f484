#!/usr/bin/env bash
# The whole CI suite under AddressSanitizer + UndefinedBehaviorSanitizer:
# configures the preset asan-suite (build-asan-suite/: gcc, -O2 with
# assertions, no fuzz coverage), builds everything and runs ctest -LE validation
# there. (The fuzzing preset asan-clang, -O1 with libFuzzer's coverage in every
# library, ran the suite 100-130 times slower than Release: its DEM-heavy tests,
# such as a dense agglomerate's packing, took over an hour each.) Any sanitizer report fails its test (UBSan
# halts on the first error; leaks are reported by LeakSanitizer except inside
# the GL libraries, scripts/sanitizer-suppressions.txt).
#   scripts/sanitize.sh [-jN]        (default -j2; run it with nice on a shared machine)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=${1:--j2}
cd "$root"
[[ -f build-asan-suite/CMakeCache.txt ]] || cmake --preset asan-suite
cmake --build build-asan-suite "$jobs"
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export LSAN_OPTIONS=suppressions=$root/scripts/sanitizer-suppressions.txt:print_suppressions=0
# The sanitized build runs several times slower: a longer per-test limit.
ctest --test-dir build-asan-suite -LE validation "$jobs" --timeout 3000 --output-on-failure
