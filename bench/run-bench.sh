#!/usr/bin/env bash
# Times rocklab and LIGGGHTS on the same scenes, in one run, and prints
# particle-steps per second for each, their ratio, rocklab's 2-thread speed-up
# and its memory per particle.
#
# Usage: bench/run-bench.sh [settle|dense|clumps|chute|grid|order|render|track|memory|all] [small|full] [OUTDIR]
#   scene  settle (contact-sparse), dense (contact-rich), clumps (the chute's four-ball clump
#          landing in a box, then sheared by a sliding floor; ball-steps/s, i.e. clump members,
#          and member contacts per clump in both engines as the check), grid (7:1 size ratio:
#          multi-level against single-level neighbour grid, rocklab only), chute (the clump chute
#          job, chute-30-clumps deposit to clearance with camera and tracking, against its LIGGGHTS
#          twin; whole-process wall times; not part of all: about 25 min small, an hour full), order (the dense
#          lattice in lattice order against the same spheres shuffled in memory, rocklab only), render
#          (frames/s of the OSMesa renderer for 7,000 spheres at 640x480 and
#          1280x1024, rocklab only), track (marker detection + linking frames/s on
#          the same frames), memory (rocklab's peak-RSS growth per sphere on settle
#          and dense, N = 2000 to 54000, one thread, 200 steps: not a timing, so it
#          may run beside other work) or all (default: every timing, not memory)
#   sizes  small: N = 2000 only (clumps: 1,700 clumps); full (default): N = 2000, 16000, 54000
#          (clumps: 1,700 and 12,000 clumps, 6,800 and 48,000 balls)
#   OUTDIR logs and results (default: a new temporary directory)
# Needs: a built rocklab (bash scripts/setup.sh). The peer, LIGGGHTS 3.8 and mpirun, is
# installed where missing by scripts/install-peer.sh (Debian's package without its
# recommends, which would remove libvtk9-dev for ParaView; it refuses any install that
# removes a package and checks that rocklab still configures); ROCKLAB_BENCH_PEER=skip
# runs rocklab alone.
# Both engines run the same lattice, walls, contact law (linear, 1e9 N/m per contact,
# friction 0.37, tangential history, no damping), dt = 1e-6 s, skin 2 mm and step count.
# The clumps scene has the same clump (members, mass, principal moments), box, insertion region,
# law (plus a normal dashpot, so that a bed forms), dt and phases in both, but each engine inserts
# with its own random stream: the two agree statistically (docs/performance.md), hence the check
# column from both.
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
case $which_scenes in all|settle|dense|clumps|chute)  # the scenes with a peer: install it where missing
  if [ "${ROCKLAB_BENCH_PEER:-install}" = skip ]; then
    have_peer=0; echo "ROCKLAB_BENCH_PEER=skip: rocklab alone, peer columns empty" >&2
  elif ! { command -v liggghts >/dev/null && command -v mpirun >/dev/null; } && ! "$root/scripts/install-peer.sh"; then
    have_peer=0; echo "liggghts not installed: peer columns empty" >&2
  fi ;;
esac

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

run_peer() {  # scene n procs steps [VAR VALUE]... -> sets pps (n x steps / s), peer_log
  local scene=$1 n=$2 np=$3 steps=$4; shift 4
  pps=""
  [ $have_peer = 1 ] || return 0
  peer_log="$out/liggghts-$scene-$n-$np.log"
  local vars=()
  while [ $# -ge 2 ]; do vars+=(-var "$1" "$2"); shift 2; done
  (cd "$out" && mpirun --allow-run-as-root --oversubscribe -np "$np" liggghts -in "$root/bench/liggghts/$scene.liggghts" \
    "${vars[@]}" -log none >"$peer_log" 2>&1)
  # Loop time of every run but a one-step one (the clumps' insertion step, not timed in rocklab either).
  local t; t=$(awk '/^Loop time of/ && $9 > 1 { s += $4 } END { print s }' "$peer_log")
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

case $which_scenes in all|settle|dense)
  printf 'scene,N,steps,rocklab_1t,rocklab_2t,speedup_2t,liggghts_1p,liggghts_2p,ratio_1core,ratio_2core,rocklab_bytes_per_particle,touching_pairs_per_sphere\n' ;;
esac
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
    run_peer $scene $n 1 "$steps" NX $nx NY $ny NZ $nz STEPS "$steps"; l1=$pps
    run_peer $scene $n 2 "$steps" NX $nx NY $ny NZ $nz STEPS "$steps"; l2=$pps
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

# Clumps: N four-ball clumps in a W x W box (W grows as sqrt(N): the same 0.1 m high insertion
# region at a solid fraction of 0.15), SETTLE steps on a fixed floor, then SHEAR steps on a floor
# sliding at 0.5 m/s. Throughput in ball-steps/s (4 balls a clump: rocklab's particle_steps_per_s,
# LIGGGHTS' atoms x steps / loop time); the check, from each engine at the last step: touching
# member pairs of different clumps per clump, and the mean height of the clumps' centres (mm;
# rocklab: its gravitational energy / (total mass x g)).
if [ "$which_scenes" = all ] || [ "$which_scenes" = clumps ]; then
  printf '\nscene,clumps,balls,steps,rocklab_1t,rocklab_2t,speedup_2t,liggghts_1p,liggghts_2p,ratio_1core,ratio_2core,contacts_per_clump_rocklab,contacts_per_clump_liggghts,mean_height_mm_rocklab,mean_height_mm_liggghts\n'
  specs=("1700 0.72 30000 20000" "12000 1.913 30000 20000")  # N, W (m), SETTLE, SHEAR
  [ "$sizes" = full ] || specs=("${specs[0]}")
  for spec in "${specs[@]}"; do
    set -- $spec
    nc=$1 w=$2 settle=$3 shear=$4 n=$((4 * $1)) steps=$(($3 + $4))
    # rocklab runs the peer's insertion step too (steps + 1); the floors swap after step
    # settle + 1 as in the peer (to within a step: the switch time lies between two steps).
    switch=$(calc "($settle + 0.5) * 0.000001")  # bc reads no exponent
    args=(--set "particles.0.count=$nc" --set "particles.0.region_max=[$w,$w,0.1]"
          --set "walls.xmax.point=[$w,0,0]" --set "walls.ymax.point=[0,$w,0]"
          --set "walls.floor.active_until=$switch" --set "walls.shear_floor.active_from=$switch")
    run_rocklab clumps $nc 1 $((steps + 1)) "${args[@]}"; r1=$ps; touch_r=$touch
    res="$out/rocklab-clumps-$nc-1/results.json"
    height_r=$(echo "1000 * $(json "$res" potential_gravity) / ($nc * $(json "$res" mass_kg) * 9.81)" | bc -l)
    run_rocklab clumps $nc 2 $((steps + 1)) "${args[@]}"; r2=$ps
    # rocklab's rate is over its particles_at_start balls: the same n.
    touch_l=""; height_l=""
    run_peer clumps $n 1 "$steps" N $nc W $w SETTLE $settle SHEAR $shear; l1=$pps
    # the last thermo line (step atoms ke cpc cz cpu): member contacts per clump, mean height (m)
    if [ -n "$l1" ]; then
      read -r touch_l height_l < <(awk 'NF == 6 && $1 ~ /^[0-9]+$/ && $2 ~ /^[0-9]+$/ { c = $4; z = $5 } END { print c, 1000 * z }' "$peer_log")
    fi
    run_peer clumps $n 2 "$steps" N $nc W $w SETTLE $settle SHEAR $shear; l2=$pps
    ratio1=""; ratio2=""
    [ -z "$l1" ] || ratio1=$(echo "$r1 / $l1" | bc -l)
    [ -z "$l2" ] || ratio2=$(echo "$r2 / $l2" | bc -l)
    printf 'clumps,%d,%d,%d,%.3g,%.3g,%.2f,%s,%s,%s,%s,%.3g,%s,%.1f,%s\n' $nc $n $steps "$r1" "$r2" "$(echo "$r2 / $r1" | bc -l)" \
      "$( [ -z "$l1" ] || printf %.3g "$l1")" "$( [ -z "$l2" ] || printf %.3g "$l2")" \
      "$( [ -z "$ratio1" ] || printf %.2f "$ratio1")" "$( [ -z "$ratio2" ] || printf %.2f "$ratio2")" "$touch_r" \
      "$( [ -z "$touch_l" ] || printf %.3g "$touch_l")" "$height_r" "$( [ -z "$height_l" ] || printf %.1f "$height_l")"
  done
fi

# The clump chute job (issue 22): chute-30-clumps as users run it (its camera and tracking on,
# rocklab's automatic step), deposit to clearance, against bench/liggghts/chute-clumps.liggghts
# given the same simulated times at dt = 1e-6 s: rocklab's deposit end, gate opening and last
# discharge. Wall time of each whole process (start-up and output included), seconds. small:
# rocklab on 2 threads and LIGGGHTS on 1 process (the issue's comparison); full: both engines on 1
# and 2. The check: the clumps LIGGGHTS still holds at the end (rocklab's are all out).
# ROCKLAB_CHUTE_ARGS: more arguments for rocklab's runs, e.g. the larger step the issue allows
# where the contact-network check accepts it: "--set timestep.dt=9e-7 --set timestep.allow_unsafe=true".
if [ "$which_scenes" = chute ]; then
  printf '\nchute,clumps,simulated_s,rocklab_1t_s,rocklab_2t_s,liggghts_1p_s,liggghts_2p_s,ratio_2t_vs_1p,ratio_1t_vs_1p,ratio_2t_vs_2p,clearance_s,clumps_left_liggghts\n'
  seconds() { date +%s.%N; }
  chute_rocklab() {  # threads -> sets wall (s); the run folder rocklab-chute-T
    local dir="$out/rocklab-chute-$1" t0; t0=$(seconds)
    # shellcheck disable=SC2086  # ROCKLAB_CHUTE_ARGS is a list of words on purpose
    "$rocklab" run "$root/assets/scenes/chute-30-clumps.toml" --out "$dir" --overwrite --threads "$1" --quiet \
      ${ROCKLAB_CHUTE_ARGS:-} >"$dir.log" 2>&1
    wall=$(echo "$(seconds) - $t0" | bc -l)
  }
  chute_peer() {  # procs -> sets pwall (s) and left (clumps at the end); empty without the peer
    pwall=""; left=""
    [ $have_peer = 1 ] || return 0
    local log="$out/liggghts-chute-$1.log" t0; t0=$(seconds)
    (cd "$out" && mpirun --allow-run-as-root --oversubscribe -np "$1" liggghts -in "$root/bench/liggghts/chute-clumps.liggghts" \
      -var N 1680 -var INCL 30 -var DEPOSIT "$deposit" -var TILT "$tilt" -var FLOW "$flow" -log none >"$log" 2>&1)
    pwall=$(echo "$(seconds) - $t0" | bc -l)
    left=$(awk 'NF == 5 && $1 ~ /^[0-9]+$/ && $2 ~ /^[0-9.]+$/ { c = $2 } END { print c }' "$log")
  }
  r1=""; l2=""
  chute_rocklab 2; r2=$wall
  res="$out/rocklab-chute-2/results.json"
  # The peer's steps at its dt of 1e-6 s for rocklab's phase times.
  deposit=$(printf '%.0f' "$(echo "$(json "$res" deposit_end_s) * 1000000" | bc -l)")
  tilt=$(printf '%.0f' "$(echo "($(json "$res" gate_open_s) - $(json "$res" deposit_end_s)) * 1000000" | bc -l)")
  flow=$(printf '%.0f' "$(echo "($(json "$res" simulated_time_s) - $(json "$res" gate_open_s)) * 1000000" | bc -l)")
  chute_peer 1; l1=$pwall; left1=$left
  if [ "$sizes" = full ]; then chute_rocklab 1; r1=$wall; chute_peer 2; l2=$pwall; fi
  ratio() { [ -z "$1" ] || [ -z "$2" ] || printf %.2f "$(echo "$2 / $1" | bc -l)"; }  # peer time / rocklab time
  printf 'chute,1680,%s,%s,%.0f,%s,%s,%s,%s,%s,%s,%s\n' "$(json "$res" simulated_time_s)" "$( [ -z "$r1" ] || printf %.0f "$r1")" "$r2" \
    "$( [ -z "$l1" ] || printf %.0f "$l1")" "$( [ -z "$l2" ] || printf %.0f "$l2")" "$(ratio "$r2" "$l1")" "$(ratio "$r1" "$l1")" \
    "$(ratio "$r2" "$l2")" "$(json "$res" clearance_time_s)" "$left1"
fi

# Memory order: the dense lattice (N = 16,000, or 2,000 with small) given as a list of its
# positions, once in lattice order and once shuffled (fixed seed): the same spheres, contacts
# and steps, so the ratio is what neighbours scattered in memory cost (rocklab only, one thread).
if [ "$which_scenes" = all ] || [ "$which_scenes" = order ]; then
  printf '\norder,N,steps,particle_steps_per_s\n'
  read -r nx nz steps < <([ "$sizes" = full ] && echo "20 10 1500" || echo "10 5 6000")
  for order in lattice shuffled; do
    scene="$out/order-$order.toml"
    # The dense scene up to its particles, the box for nx x nx x nz cells, then the list.
    sed '/^\[\[particles\]\]/,$d' "$root/bench/scenes/dense.toml" >"$scene"
    awk -v nx=$nx -v nz=$nz -v order=$order 'BEGIN {
      a = 0.0282842712474619; split("0 0 0 0.5 0.5 0 0.5 0 0.5 0 0.5 0.5", b, " ")
      for (k = 0; k < nz; ++k) for (j = 0; j < nx; ++j) for (i = 0; i < nx; ++i) for (q = 0; q < 4; ++q)
        p[n++] = sprintf("[%.17g,%.17g,%.17g]", (i + 0.25 + b[3*q+1]) * a, (j + 0.25 + b[3*q+2]) * a, (k + 0.25 + b[3*q+3]) * a)
      if (order == "shuffled") { srand(1); for (m = n - 1; m > 0; --m) { r = int(rand() * (m + 1)); t = p[m]; p[m] = p[r]; p[r] = t } }
      print "[[particles]]\ntype = \"list\"\nmaterial = \"ball\"\nradius = 0.01\npositions = ["
      for (m = 0; m < n; ++m) print p[m] (m < n - 1 ? "," : "]")
      print "[output]\nhdf5 = false\ncheckpoint = false"
    }' >>"$scene"
    dir="$out/rocklab-order-$order"
    "$rocklab" run "$scene" --out "$dir" --overwrite --threads 1 --quiet --set scene.steps=$steps \
      --set "walls.0.max=[$(calc "($nx-0.25)*0.0282842712474619+0.01"),$(calc "($nx-0.25)*0.0282842712474619+0.01"),$(calc "($nz+1)*0.0282842712474619")]" >"$dir.log" 2>&1
    printf '%s,%s,%s,%.3g\n' $order "$(json "$dir/results.json" particles)" $steps "$(json "$dir/results.json" particle_steps_per_s)"
  done
fi

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
