#!/usr/bin/env bash
# The clump benchmarks' twins describe one body: the mass and principal moments written into
# bench/liggghts/clumps.liggghts and chute-clumps.liggghts are those rocklab computes for
# bench/scenes/clumps.toml's clump (results.json clump_shapes; the chute's clump has the same member
# radius), and their contact stiffness and dashpots are rocklab's for that mass (the box scene's
# normal dashpot; the chute's series stiffness and both dashpots of assets/scenes/chute-30-clumps.toml).
# Fails, naming the number, when rocklab's clump, its mass rule or a scene's springs or damping
# change and a peer's input was not updated. Runs rocklab for one step on 5 clumps.
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
status=0
same() {  # same NAME ROCKLAB PEER: equal to 1e-9 relative
  if awk -v a="$2" -v b="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; s = (a < 0 ? -a : a); exit !(d <= 1e-9 * s || (s == 0 && d == 0)) }'; then
    echo "ok   $1: rocklab $2, peer $3"
  else
    echo "DIFF $1: rocklab $2, peer $3 ($peer)" >&2; status=1
  fi
}
key() {  # key FILE NAME -> the first "NAME = number" of a scene file
  sed -n "s/^$2 *= *\([0-9.e+-]*\).*/\1/p" "$1" | head -1
}
dashpot() {  # dashpot BETA K -> 2 beta sqrt(m k), m the clump's mass (a member's dashpot sees its clump;
             # equal clumps average m and m; a wall contact takes the ball's clump)
  awk -v b="${1:-0}" -v k="$2" -v m="$mass" 'BEGIN { printf "%.17g", 2 * b * sqrt(m * k) }'
}
# Both peers: the benchmark's clump box and the clump chute job (the chute's clump is the same:
# its member radius is checked against the box scene's).
for peer in "$root/bench/liggghts/clumps.liggghts" "$root/bench/liggghts/chute-clumps.liggghts"; do
  # peer: "mass M inertia_tensor Ixx Ixy Ixz Iyy Iyz Izz"
  read -r pm pxx pxy pxz pyy pyz pzz < <(sed -n 's/.* mass \([^ ]*\) inertia_tensor \([^ ]*\) \([^ ]*\) \([^ ]*\) \([^ ]*\) \([^ ]*\) \([^ ]*\).*/\1 \2 \3 \4 \5 \6 \7/p' "$peer") || true
  [ -n "${pzz:-}" ] || { echo "$peer: no 'mass M inertia_tensor Ixx Ixy Ixz Iyy Iyz Izz' line" >&2; exit 1; }
  same "mass (kg)" "$mass" "$pm"
  same "Ixx (kg m2)" "$i1" "$pxx"
  same "Iyy (kg m2)" "$i2" "$pyy"
  same "Izz (kg m2)" "$i3" "$pzz"
  same "Ixy" 0 "$pxy"; same "Ixz" 0 "$pxz"; same "Iyz" 0 "$pyz"
  gamman=$(sed -n 's/^fix .* gamman_abs peratomtypepair 1 \([^ ]*\).*/\1/p' "$peer")
  if [ "${peer##*/}" = clumps.liggghts ]; then
    # The box's normal dashpot on k = 1e9 N/m per contact; no shear dashpot.
    same "normal dashpot (N s/m)" "$(dashpot "$(key "$root/bench/scenes/clumps.toml" damping_normal)" 1e9)" "${gamman:-missing}"
  else
    chute=$root/assets/scenes/chute-30-clumps.toml
    same "member radius (m)" "$(key "$root/bench/scenes/clumps.toml" member_radius)" "$(key "$chute" member_radius)"
    # Table 4.1's kn = ks per entity, in series: half of it per contact (ball-ball and ball-wall alike).
    k=$(awk -v k="$(key "$chute" kn)" 'BEGIN { printf "%.17g", k / 2 }')
    same "contact stiffness (N/m)" "$k" "$(sed -n 's/^fix .* kn peratomtypepair 1 \([^ ]*\).*/\1/p' "$peer")"
    same "normal dashpot (N s/m)" "$(dashpot "$(key "$chute" damping_normal)" "$k")" "${gamman:-missing}"
    same "shear dashpot (N s/m)" "$(dashpot "$(key "$chute" damping_shear)" "$k")" \
      "$(sed -n 's/^fix .* gammat_abs peratomtypepair 1 \([^ ]*\).*/\1/p' "$peer")"
  fi
done
exit $status
