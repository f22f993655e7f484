#!/usr/bin/env bash
# Times rocklab and LIGGGHTS on the same scenes, in one run, and prints
# particle-steps per second for each, their ratio, rocklab's 2-thread speed-up
# and its memory per particle.
#
# Usage: bench/run-bench.sh [settle|dense|grid|render|track|memory|all] [small|full] [OUTDIR]
#   scene  settle (contact-sparse), dense (contact-rich), grid (7:1 size ratio:
#          multi-level against single-level neighbour grid, rocklab only), render
#          (frames/s of the OSMesa renderer for 7,000 spheres at 640x480 and
#          1280x1024, rocklab only), track (marker detection + linking frames/s on
#          the same frames), memory (rocklab's peak-RSS growth per sphere on settle
#          and dense, N = 2000 to 54000, one thread, 200 steps: not a timing, so it
#          may run beside other work) or all (default: every timing, not memory)
#   sizes  small: N = 2000 only; full (default): N = 2000, 16000, 54000
#   OUTDIR logs and results (default: a new temporary directory)
# Needs: a built rocklab (bash scripts/setup.sh) and, for the peer, `apt-get install
# --no-install-recommends liggghts` (with its recommends apt removes libvtk9-dev for
# ParaView, and rocklab no longer configures).
# Both engines run the same lattice, walls, contact law (linear, 1e9 N/m per contact,
# friction 0.37, tangential history, no damping), dt = 1e-6 s, skin 2 mm and step count.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
rocklab="${ROCKLAB_BIN:-$root/build/app/rocklab}"  # ROCKLAB_BIN: another build (old against new)
[ -x "$rocklab" ] || { echo "build rocklab first: bash scripts/setup.sh" >&2; exit 2; }
which_scenes=${1:-all}
sizes=${2:-full}
out=${3:-$(mktemp -d)}
mkdir -p "$out"
echo "logs in $out" >&2
have_peer=1
command -v liggghts >/dev/null && command -v mpirun >/dev/null || { have_peer=0; echo "liggghts not installed: peer columns empty" >&2; }

calc() {  # calc EXPR -> the value with a leading zero (bc prints .5, which TOML refuses)
  printf '%.17g' "$(echo "$1" | bc -l)"
}

json() {  # json FILE KEY -> first numeric value of "KEY": in the file
  sed -n "s/.*\"$2\": \([-0-9.e+]*\).*/\1/p" "$1" | head -1
}

run_rocklab() {  # scene n threads steps args... -> sets ps (particle-steps/s), rss (bytes), touch (pairs/sphere)
  local scene=$1 n=$2 t=$3 steps=$4; shift 4
  local dir="$out/rocklab-$scene-$n-$t"
  "$rocklab" run "$root/bench/scenes/$scene.toml" --out "$dir" --overwrite --threads "$t" --quiet \
    --set scene.steps="$steps" "$@" >"$dir.log" 2>&1
  ps=$(json "$dir/results.json" particle_steps_per_s)
  rss=$(json "$dir/results.json" peak_rss_bytes)
  local contacts; contacts=$(json "$dir/results.json" contacts)
  touch=$(echo "$contacts / $n" | bc -l)
}

run_peer() {  # scene n procs steps NX NY NZ -> sets pps
  local scene=$1 n=$2 np=$3 steps=$4
  pps=""
  [ $have_peer = 1 ] || return 0
  local log="$out/liggghts-$scene-$n-$np.log"
  (cd "$out" && mpirun --allow-run-as-root --oversubscribe -np "$np" liggghts -in "$root/bench/liggghts/$scene.liggghts" \
    -var NX "$5" -var NY "$6" -var NZ "$7" -var STEPS "$steps" -log none >"$log" 2>&1)
  local t; t=$(sed -n 's/^Loop time of \([0-9.e+-]*\) on.*/\1/p' "$log" | tail -1)
  pps=$(echo "$n * $steps / $t" | bc -l)
}

box_args() {  # box_args scene nx ny nz -> sets args: the lattice counts and the box of bench/liggghts
  local scene=$1 nx=$2 ny=$3 nz=$4
  if [ $scene = settle ]; then  # box as in settle.liggghts
    args=(--set "walls.0.max=[$(calc "$nx*0.0232+0.012"),$(calc "$ny*0.0232+0.012"),$(calc "$nz*0.0232*1.2")]")
  else                          # box as in dense.liggghts: (N - 0.25) a + 0.01
    local a=0.0282842712474619
    args=(--set "walls.0.max=[$(calc "($nx-0.25)*$a+0.01"),$(calc "($ny-0.25)*$a+0.01"),$(calc "($nz+1)*$a")]")
  fi
  args+=(--set "particles.0.counts=[$nx,$ny,$nz]")
}

# Memory: peak-RSS growth per sphere from N = 2000 (removes the fixed cost), one thread.
if [ "$which_scenes" = memory ]; then
  printf 'scene,N,steps,peak_rss_bytes,bytes_per_particle_from_2000\n'
  for scene in settle dense; do
    case $scene in
      settle) per=2; specs=("10 10 10" "20 20 20" "30 30 30") ;;
      dense)  per=4; specs=("10 10 5" "20 20 10" "30 30 15") ;;
    esac
    rss_small=""
    for spec in "${specs[@]}"; do
      set -- $spec
      n=$((per * $1 * $2 * $3))
      box_args $scene $1 $2 $3
      run_rocklab $scene $n 1 200 "${args[@]}"
      if [ -z "$rss_small" ]; then rss_small=$rss; n_small=$n; bpp=""; else bpp=$(echo "($rss - $rss_small) / ($n - $n_small)" | bc); fi
      printf '%s,%d,200,%s,%s\n' $scene $n "$rss" "$bpp"
    done
  done
  exit 0
fi

printf 'scene,N,steps,rocklab_1t,rocklab_2t,speedup_2t,liggghts_1p,liggghts_2p,ratio_1core,ratio_2core,rocklab_bytes_per_particle,touching_pairs_per_sphere\n'
for scene in settle dense; do
  [ "$which_scenes" = all ] || [ "$which_scenes" = "$scene" ] || continue
  case $scene in
    settle) per=2; specs=("10 10 10 50000" "20 20 20 20000" "30 30 30 10000") ;;
    dense)  per=4; specs=("10 10 5 20000" "20 20 10 4000" "30 30 15 1500") ;;
  esac
  [ "$sizes" = full ] || specs=("${specs[0]}")
  rss_small=""; n_small=""
  for spec in "${specs[@]}"; do
    set -- $spec
    nx=$1 ny=$2 nz=$3 steps=$4 n=$((per * $1 * $2 * $3))
    box_args $scene $nx $ny $nz
    run_rocklab $scene $n 1 "$steps" "${args[@]}"; r1=$ps; rss1=$rss
    run_rocklab $scene $n 2 "$steps" "${args[@]}"; r2=$ps
    run_peer $scene $n 1 "$steps" $nx $ny $nz; l1=$pps
    run_peer $scene $n 2 "$steps" $nx $ny $nz; l2=$pps
    # Memory per particle: growth of peak RSS from the smallest size (removes the fixed cost).
    if [ -z "$rss_small" ]; then rss_small=$rss1; n_small=$n; bpp=""; else bpp=$(echo "($rss1 - $rss_small) / ($n - $n_small)" | bc); fi
    ratio1=""; ratio2=""
    [ -z "$l1" ] || ratio1=$(echo "$r1 / $l1" | bc -l)
    [ -z "$l2" ] || ratio2=$(echo "$r2 / $l2" | bc -l)
    printf '%s,%d,%d,%.3g,%.3g,%.2f,%s,%s,%s,%s,%s,%.2f\n' $scene $n $steps "$r1" "$r2" "$(echo "$r2 / $r1" | bc -l)" \
      "$( [ -z "$l1" ] || printf %.3g "$l1")" "$( [ -z "$l2" ] || printf %.3g "$l2")" \
      "$( [ -z "$ratio1" ] || printf %.2f "$ratio1")" "$( [ -z "$ratio2" ] || printf %.2f "$ratio2")" "$bpp" "$touch"
  done
done

# Neighbour grid at a 7:1 size ratio: the multi-level grid against one level whose
# cells are sized by the largest sphere (neighbours.max_levels = 1).
if [ "$which_scenes" = all ] || [ "$which_scenes" = grid ]; then
  printf '\ngrid_levels,N,steps,rebuilds,neighbour_ms_per_rebuild,particle_steps_per_s\n'
  for lv in 8 1; do
    dir="$out/rocklab-grid-$lv"
    "$rocklab" run "$root/bench/scenes/polydisperse.toml" --out "$dir" --overwrite --threads 1 --quiet \
      --set neighbours.max_levels=$lv >"$dir.log" 2>&1
    rb=$(json "$dir/results.json" neighbour_rebuilds)
    printf '%s,%s,%s,%s,%.2f,%.3g\n' "$( [ $lv = 1 ] && echo single || echo multi)" "$(json "$dir/results.json" particles)" \
      "$(json "$dir/results.json" steps)" "$rb" "$(echo "1000 * $(json "$dir/results.json" neighbour_search_s) / $rb" | bc -l)" \
      "$(json "$dir/results.json" particle_steps_per_s)"
  done
fi

# Renderer: frames per second for a chute-like frame of 7,000 spheres.
if [ "$which_scenes" = all ] || [ "$which_scenes" = render ]; then
  cmake --build "$root/build" --target render_benchmark >/dev/null
  printf '\nrender\n'
  "$root/build/tests/render_benchmark"
fi

# Tracker: detection + linking frames per second on rendered frames with 20 markers.
if [ "$which_scenes" = all ] || [ "$which_scenes" = track ]; then
  cmake --build "$root/build" --target track_benchmark >/dev/null
  printf '\ntrack\n'
  "$root/build/tests/track_benchmark"
fi
