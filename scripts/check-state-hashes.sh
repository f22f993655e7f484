#!/usr/bin/env bash
# Guards refactors: runs scenes to a short end time and compares the final
# state hash (results.json "state_hash": positions, velocities, spins, clump
# angular momenta; equal hash = bitwise equal state) with the recorded one in
# scripts/state-hashes.txt. A moved line of engine code must not change a bit.
#
# Usage: scripts/check-state-hashes.sh [--record] [--bin ROCKLAB] [--quick] [--keep DIR]
#   --record  rewrite the hash column from this binary (only when a change of
#             results is intended: say why in the commit)
#   --bin     the rocklab executable (default: build/app/rocklab)
#   --quick   only the rows marked "quick" (CI: ctest label `hashes`, ~1 min)
#   --keep    keep the run folders in DIR (default: a temporary folder, removed)
# Exit: 0 every hash equal, 1 a hash differs or a run failed, 2 bad usage.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
table="$root/scripts/state-hashes.txt"
bin="$root/build/app/rocklab"
record=0
quick=0
keep=""
while (($#)); do
  case "$1" in
    --record) record=1 ;;
    --quick) quick=1 ;;
    --bin) bin=${2:?--bin needs a path}; shift ;;
    --keep) keep=${2:?--keep needs a folder}; shift ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "check-state-hashes: unknown argument '$1' (allowed: --record, --bin PATH, --quick, --keep DIR)" >&2; exit 2 ;;
  esac
  shift
done
[ -x "$bin" ] || { echo "check-state-hashes: no executable '$bin' (build first: bash scripts/setup.sh)" >&2; exit 2; }
[ -f "$table" ] || { echo "check-state-hashes: missing table $table" >&2; exit 2; }
if [ -n "$keep" ]; then work=$keep; mkdir -p "$work"; else work=$(mktemp -d); trap 'rm -rf "$work"' EXIT; fi

# Table rows: tag | scene | --set overrides (space separated) | state hash
failed=0
new_table=$(mktemp)
row=0
while IFS= read -r line; do
  if [[ -z "$line" || "$line" == \#* ]]; then echo "$line" >>"$new_table"; continue; fi
  IFS='|' read -r tag scene sets expected <<<"$line"
  tag=$(echo "$tag" | xargs); scene=$(echo "$scene" | xargs); expected=$(echo "$expected" | xargs)
  row=$((row + 1))
  if ((quick)) && [ "$tag" != quick ]; then echo "$line" >>"$new_table"; continue; fi
  args=()
  for s in $sets; do args+=(--set "$s"); done
  # Scenes named by path are relative to the repository root.
  [[ "$scene" == */* ]] && scene="$root/$scene"
  dir="$work/$row"
  start=$(date +%s.%N)
  set +e
  "$bin" run "$scene" --out "$dir" --overwrite --threads 1 --quiet "${args[@]}" >"$dir.log" 2>&1
  rc=$?
  set -e
  secs=$(printf '%.1f' "$(echo "$(date +%s.%N) - $start" | bc -l)")
  got=$(sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p' "$dir/results.json" 2>/dev/null | head -1)
  label="$(basename "$scene" .toml)${sets:+ ($(echo "$sets" | xargs))}"
  if [ -z "$got" ]; then
    echo "FAIL  $label: no state hash (exit $rc; log $dir.log)"; tail -3 "$dir.log" | sed 's/^/      /'
    failed=1; echo "$line" >>"$new_table"; continue
  fi
  if ((record)); then
    printf '%s | %s | %s | %s\n' "$tag" "$(echo "$line" | cut -d'|' -f2 | xargs)" "$(echo "$sets" | xargs)" "$got" >>"$new_table"
    echo "rec   $label: $got (${secs} s)"
  elif [ "$got" == "$expected" ]; then
    echo "ok    $label: $got (${secs} s)"; echo "$line" >>"$new_table"
  else
    echo "FAIL  $label: $got, recorded $expected (${secs} s)"; failed=1; echo "$line" >>"$new_table"
  fi
done <"$table"
if ((record)); then mv "$new_table" "$table"; echo "recorded in $table"; else rm -f "$new_table"; fi
((failed == 0)) && echo "state hashes: all equal" || echo "state hashes: DIFFERENT (see FAIL lines)"
exit "$failed"
