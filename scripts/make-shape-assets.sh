#!/usr/bin/env bash
# Regenerates the seeded particle meshes of assets/meshes/ and the pebble clumps of
# assets/clumps/ used by assets/scenes/chute-30-mesh-clumps.toml (docs/shape.md).
# Usage: scripts/make-shape-assets.sh [build/app/rocklab]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
rocklab=${1:-$root/build/app/rocklab}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$root"
# Meshes: 20 mm equivalent diameter, written in millimetres like most scanners.
for seed in 1 2 3; do
  "$rocklab" shape assets/meshes/pebble-$seed.stl --generate pebble --seed $seed --unit mm --size 0.02 --no-preview --out "$tmp/p$seed"
done
"$rocklab" shape assets/meshes/crushed-1.ply --generate crushed --seed 1 --unit mm --size 0.02 --no-preview --out "$tmp/c1"
"$rocklab" shape assets/meshes/flake-1.obj --generate flake --seed 1 --unit mm --size 0.02 --no-preview --out "$tmp/f1"
# Chute clumps: the pebbles at the study's 19.9 mm (the Eq 4-2 equivalent diameter of its
# four-ball clumps, so each pebble has the four-ball clump's mass), 16 spheres each.
for seed in 1 2 3; do
  "$rocklab" shape assets/meshes/pebble-$seed.stl --unit mm --size 0.0199 --spheres 16 --no-preview --out "$tmp/chute$seed"
  cp "$tmp/chute$seed/clump.txt" assets/clumps/pebble-$seed.txt
  echo "pebble-$seed: keys for the scene (mass, principal_inertia at 2730 kg/m^3):"
  grep -E "^(mass|principal_inertia)" "$tmp/chute$seed/clump.toml"
done
# The clump-resolution study (assets/studies/chute-clump-resolution.toml): pebble-1 as
# 1 and 4 spheres beside its 16-sphere clump above.
for n in 1 4; do
  "$rocklab" shape assets/meshes/pebble-1.stl --unit mm --size 0.0199 --spheres $n --no-preview --out "$tmp/res$n"
  cp "$tmp/res$n/clump.txt" assets/clumps/pebble-1-s$n.txt
done
