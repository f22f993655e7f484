#!/usr/bin/env bash
# Builds the libFuzzer targets (clang preset asan-clang: ASan + UBSan, build-asan/)
# and runs each for a bounded time from its seed corpus (tests/fuzz/corpus/).
#   scripts/fuzz.sh [--seconds N] [--no-build] [--keep-going] [--bin-dir DIR] [TARGET...]
# TARGET: scene mesh checkpoint run_file collect (default: all). A crash, leak,
# timeout or sanitizer report stops that target, leaves the input in
# <bin-dir>/findings/ and makes the script exit 1; each target prints its time
# and number of executions. Reproduce a finding: <bin-dir>/fuzz_TARGET FILE.
# --keep-going: fork mode that records every finding and goes on (while a known
# one is not fixed yet, the others behind it are still found).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=60 build=1 keep_going=() bin_dir="$root/build-asan/tests/fuzz" targets=()
while (($#)); do
  case "$1" in
    --seconds) seconds=$2; shift 2 ;;
    --no-build) build=0; shift ;;
    --keep-going) keep_going=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1); shift ;;
    --bin-dir) bin_dir=$2; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
((${#targets[@]})) || targets=(scene mesh checkpoint run_file collect)

if ((build)); then
  [[ -f "$root/build-asan/CMakeCache.txt" ]] || cmake --preset asan-clang -S "$root"
  nice -n 10 cmake --build "$root/build-asan" -j2 --target $(printf 'fuzz_%s ' "${targets[@]}")
fi

# UBSan findings stop the run like ASan's; leaks inside libOSMesa are not ours.
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
# Full stacks for leaks, so that the suppressions can match library frames.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:fast_unwind_on_malloc=0}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/scripts/sanitizer-suppressions.txt:print_suppressions=0}
# The targets' scratch folders (one per process) go below the build, not /tmp.
export TMPDIR="$bin_dir/tmp"
mkdir -p "$TMPDIR"
declare -A max_len=([scene]=16384 [mesh]=16384 [checkpoint]=600 [run_file]=600 [collect]=8192)
status=0
for t in "${targets[@]}"; do
  exe="$bin_dir/fuzz_$t"
  [[ -x "$exe" ]] || { echo "fuzz: $exe is missing (configure with: cmake --preset asan-clang)" >&2; exit 2; }
  work="$bin_dir/corpus/$t" findings="$bin_dir/findings"
  mkdir -p "$work" "$findings"
  seeds=("$root/tests/fuzz/corpus/$t")
  # The built-in scenes are seeds of the scene reader too (copied: libFuzzer
  # adds to its first folder only).
  [[ $t == scene ]] && cp -n "$root"/assets/scenes/*.toml "$work/"
  log="$bin_dir/fuzz-$t.log"
  if (cd "$bin_dir" && "$exe" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=3072 \
        -max_len="${max_len[$t]:-4096}" -print_final_stats=1 -artifact_prefix="$findings/$t-" "${keep_going[@]}" \
        "$work" "${seeds[@]}") >"$log" 2>&1; then
    result="no finding"
    # Fork mode exits 0 after findings it was told to ignore: count them.
    found=$(grep -c "Test unit written\|crash-\|timeout-" "$log" || true)
    ((${#keep_going[@]} == 0 || found == 0)) || { result="FINDINGS: $found, see $findings"; status=1; }
  else
    result="FINDING: $(grep -m1 -E 'ERROR: |runtime error|deadly signal|Timeout|out-of-memory|terminate' "$log" || echo "see $log")"
    status=1
  fi
  runs=$(grep -oP 'stat::number_of_executed_units:\s*\K[0-9]+' "$log" | tail -1 || true)
  ((${#keep_going[@]} == 0)) || runs=$(grep -oP '#\K[0-9]+(?=: cov)' "$log" | tail -1 || true)
  echo "fuzz $t: ${seconds} s, $runs executions, $result (log: $log)"
done
exit $status
