#!/usr/bin/env bash
# The clump benchmark's twins describe one body: the mass and principal moments written into
# bench/liggghts/clumps.liggghts are those rocklab computes for bench/scenes/clumps.toml's clump
# (results.json clump_shapes), and its gamman is rocklab's normal dashpot for that mass. Fails,
# naming the number, when rocklab's clump, its mass rule or the scene's damping changes and the
# peer's input was not updated. Runs rocklab for one step on 5 clumps.
# Usage: bench/check-clump-twin.sh [ROCKLAB_BIN]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
rocklab=${1:-$root/build/app/rocklab}
peer=$root/bench/liggghts/clumps.liggghts
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$rocklab" run "$root/bench/scenes/clumps.toml" --out "$out/run" --overwrite --threads 1 --quiet \
  --set scene.steps=1 --set particles.0.count=5 >"$out/log" 2>&1 || { cat "$out/log" >&2; exit 1; }
# rocklab: mass and the three principal moments of the (only) clump shape
read -r mass i1 i2 i3 < <(tr -d ' \n' <"$out/run/results.json" |
  sed -n 's/.*"clump_shapes":\[{[^]]*"mass_kg":\([-0-9.e+]*\),[^]]*"principal_inertia_kg_m2":\[\([-0-9.e+]*\),\([-0-9.e+]*\),\([-0-9.e+]*\)\].*/\1 \2 \3 \4/p') || true  # (no final newline)
[ -n "${i3:-}" ] || { echo "no clump_shapes mass/principal_inertia in $out/run/results.json" >&2; exit 1; }
# peer: "mass M inertia_tensor Ixx Ixy Ixz Iyy Iyz Izz"
read -r pm pxx pxy pxz pyy pyz pzz < <(sed -n 's/.* mass \([^ ]*\) inertia_tensor \([^ ]*\) \([^ ]*\) \([^ ]*\) \([^ ]*\) \([^ ]*\) \([^ ]*\).*/\1 \2 \3 \4 \5 \6 \7/p' "$peer") || true
[ -n "${pzz:-}" ] || { echo "$peer: no 'mass M inertia_tensor Ixx Ixy Ixz Iyy Iyz Izz' line" >&2; exit 1; }
status=0
same() {  # same NAME ROCKLAB PEER: equal to 1e-9 relative
  if awk -v a="$2" -v b="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; s = (a < 0 ? -a : a); exit !(d <= 1e-9 * s || (s == 0 && d == 0)) }'; then
    echo "ok   $1: rocklab $2, peer $3"
  else
    echo "DIFF $1: rocklab $2, peer $3 ($peer)" >&2; status=1
  fi
}
same "mass (kg)" "$mass" "$pm"
same "Ixx (kg m2)" "$i1" "$pxx"
same "Iyy (kg m2)" "$i2" "$pyy"
same "Izz (kg m2)" "$i3" "$pzz"
same "Ixy" 0 "$pxy"; same "Ixz" 0 "$pxz"; same "Iyz" 0 "$pyz"
# The normal dashpot: rocklab's 2 beta sqrt(m k) (a member's dashpot sees its whole clump; equal
# clumps average m and m; k = 1e9 N/m per contact) is the peer's absolute gamman.
beta=$(sed -n 's/^damping_normal *= *\([0-9.e+-]*\).*/\1/p' "$root/bench/scenes/clumps.toml")
gamman=$(sed -n 's/^fix .* gamman_abs peratomtypepair 1 \([^ ]*\).*/\1/p' "$peer")
same "normal dashpot (N s/m)" "$(awk -v b="${beta:-0}" -v m="$mass" 'BEGIN { printf "%.17g", 2 * b * sqrt(m * 1e9) }')" "${gamman:-missing}"
exit $status
