#!/usr/bin/env bash
# Bond benchmark: bond-steps per second of the parallel-bond stage (stage 4)
# and particle-steps per second of the whole step, on 1 and 2 threads, for a
# bonded HCP block of 2.5 mm spheres (the zwick-hcp scene, made bigger, the
# top platen far away: only bonds and the contacts inside the block work).
#
# Usage: bench/bond-bench.sh [DIAMETER_M] [STEPS] [OUTDIR]
#   DIAMETER_M  agglomerate diameter (default 0.11: ~7,500 spheres, ~40,000 bonds;
#               two threads need > 5,000 balls)
#   STEPS       steps per run (default 2000)
# The peer figure, LAMMPS bpm/rotational at about 4e6 bond-steps/s per core on its
# authors' machine, is published, not measured here: Debian 12's LAMMPS (20220106)
# predates the BPM package.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
rocklab="${ROCKLAB_BIN:-$root/build/app/rocklab}"
[ -x "$rocklab" ] || { echo "build rocklab first: bash scripts/setup.sh" >&2; exit 2; }
diameter=${1:-0.11}
steps=${2:-2000}
out=${3:-$(mktemp -d)}
mkdir -p "$out"
echo "logs in $out" >&2
json() { sed -n "s/.*\"$2\": \([-0-9.e+]*\).*/\1/p" "$1" | head -1; }
printf '%-8s %10s %10s %14s %16s %14s\n' threads spheres bonds "bond stage s" "bond-steps/s" "p-steps/s"
for t in 1 2; do
  dir="$out/bonds-$t"
  "$rocklab" run zwick-hcp --out "$dir" --overwrite --threads "$t" --quiet \
    --set particles.0.diameter="$diameter" --set particles.0.position="[0,0,$diameter]" \
    --set experiment.platen_speed=1e-9 --set scene.end_time=0 --set scene.steps="$steps" --set output.hdf5=false >"$dir.log" 2>&1 ||
    { echo "run failed: $dir.log" >&2; exit 1; }
  r="$dir/results.json"
  spheres=$(json "$r" sphere_count)
  bonds=$(json "$r" bond_count)
  bond_s=$(sed -n 's/.*"bonds": \([0-9.e+-]*\).*/\1/p' "$r" | head -1)
  ps=$(json "$r" particle_steps_per_s)
  printf '%-8s %10s %10s %14.3f %16.3e %14.3e\n' "$t" "$spheres" "$bonds" "$bond_s" \
    "$(echo "$bonds * $steps / $bond_s" | bc -l)" "$ps"
done
