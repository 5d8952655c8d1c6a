#!/usr/bin/env bash
# glint benchmarks (release build; numbers are ratios measured in one run on a shared machine).
# Every measurement is a `glint bench` preset (glint bench --help lists each one's options) or
# timed `glint render` / `glint info` runs; results go to build/bench-results/, references are
# rendered once into build/bench-cache/ (by glint render --out, path tracing with its highlights
# layer, seed 777, at SIZE for REF_SECONDS) and shared by the modes.
#   1. Without a mode: path-tracing throughput against Embree's own `pathtracer` (embree-tools)
#      on the same triangles (`glint info --obj`), Lambert materials of the base colours, one
#      point light, camera, size, spp and path length, both timed as (32 spp − 1 spp); then load
#      + BVH build time and peak memory of the 1.04 M-triangle sphere grid (`glint info`).
#   2. `vsl`: the VSL paper's comparisons on the default scene: presets vsl-paper (pt, clamped
#      vpl and vsl at equal time, indirect light, 4 seeds, 10 and 60 s) and fig8 (the radius and
#      cluster sweeps), about 30 minutes plus the reference.
#   3. `hl`: the highlight paper's comparison on the default scene, against a reference of the
#      same paths (`vsl+hl --merge trace --secondary-rays 64`, HL_REF_SECONDS, default 600):
#      presets highlights (the estimator alone: traced, unmerged, merged into 1, 2, 4 lobes, for
#      N = 8, 16, 32; noise and bias from 2 seeds; the share of time spent merging) and
#      highlights-whole (the whole renderer, the highlights layers of pt and vsl+hl), about 26
#      minutes plus the reference.
#   4. `bench`: the headline, preset headline (pt, vsl and vsl+hl, 2 seeds, 2, 10 and 60 s;
#      LONG_SECONDS adds a longer budget) on builtin:atelier, doorway and showcase and the shared
#      Cornell box; then preset fig8 on showcase. About 8 minutes a scene plus the references.
#   5. `plan`: what the effect plan saves, preset plan (vsl+hl with the plan and with every pass
#      forced on, 2 seeds, 30 s) on the default scene and the shared Cornell box, about 4 minutes
#      a scene plus the references.
#   6. `suite`: where each method wins, the suite of issue 46 (an estimator that chooses per pixel
#      must be checked on every regime): preset headline at 10 and 60 s (relative L2 and MSE,
#      noise and bias from 2 seeds) on every built-in scene (bay: a directly lit half beside a bay
#      lit only indirectly), the shared Cornell box, the punctual-lights lamp and the damaged
#      helmet under the Venice sunset. About 8 minutes a scene plus the references.
#   With GLINT_BLENDER=1 (and Blender installed: scripts/deps.sh), `bench` and `suite` add each
#   scene's Blender Cycles row (tests/bench/cycles_row.py): the same camera, budgets, threads and
#   seeds, Cycles on the CPU with unbiased settings; 2 to 3 minutes more a scene.
# Environment: GLINT (a glint binary: skips installing and building), SIZE (references and
# benches, default 320x240), REF_SECONDS (default 1200), HL_REF_SECONDS (600), TIMES and SEEDS
# (replace every preset's budgets and seed count, e.g. TIMES=0.2 SEEDS=1 for a smoke run),
# LONG_SECONDS; for the throughput: TP_SIZE (640x360), TP_SPP (32), TP_DEPTH (8), TP_RUNS (3).
# Usage: tests/bench/run.sh [vsl|hl|bench|plan|suite] [SHARED_SCENES_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
mode=pt
case "${1:-}" in vsl | hl | bench | plan | suite) mode=$1; shift ;; esac
scenes=${1:-$root/../shared/scenes}
build=$root/build
if [ -n "${GLINT:-}" ]; then
  glint=$(cd "$(dirname "$GLINT")" && pwd)/$(basename "$GLINT")
else
  source "$root/scripts/deps.sh"
  glint_install_deps
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DGLINT_TESTS=OFF >/dev/null
  cmake --build "$build" -j"$(nproc)" >/dev/null
  glint=$build/app/glint
fi
size=${SIZE:-320x240}
ref_seconds=${REF_SECONDS:-1200}
cache=$build/bench-cache
results=$build/bench-results
stamp=$(date +%Y%m%d-%H%M%S)
mkdir -p "$cache" "$results"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cornell=$scenes/cornell-box/CornellBox-Original.gltf
# References are stamped with the material model (glint bench refuses another's): it keys the cache.
model=$("$glint" --version | sed -n 's/.*(material model \(.*\))$/\1/p')

# reference NAME SCENE [options]: the cached path-traced reference of SCENE (rendered when
# missing, with the options: an environment map); its path on stdout. The name holds the size and
# length, so a short smoke run never stands in for a long one.
reference() {
  local ref=$cache/$1-$size-pt${ref_seconds}s-$model.exr file=$2
  shift 2
  if [ ! -f "$ref" ]; then
    echo "rendering the path-traced reference of $file for $ref_seconds s" >&2
    "$glint" render "$file" --method pt --time "$ref_seconds" --size "$size" --seed 777 --highlights-layer \
      "$@" --out "$ref" --quiet
  fi
  echo "$ref"
}

# bench NAME SCENE REF PRESET [options]: one preset against REF, its report printed.
bench() {
  local name=$1 file=$2 ref=$3 preset=$4 out
  shift 4
  out=$results/$name-$preset-$stamp
  "$glint" bench "$file" --reference "$ref" --preset "$preset" ${TIMES:+--times "$TIMES"} \
    ${SEEDS:+--seeds "$SEEDS"} "$@" --out "$out" --quiet
  cat "$out/report.md"
}

# cycles NAME SCENE REF TIMES [--env MAP]: with GLINT_BLENDER=1 and Blender installed, the
# headline's Blender Cycles row for SCENE (tests/bench/cycles_row.py: the same camera, budgets,
# threads and seed count, unbiased settings; its noise and bias against REF), printed.
cycles() {
  [ "${GLINT_BLENDER:-}" = 1 ] || return 0
  command -v blender >/dev/null || { echo "GLINT_BLENDER=1 but blender is not installed: no Cycles row"; return 0; }
  local name=$1 file=$2 ref=$3 times=$4
  shift 4
  python3 "$root/tests/bench/cycles_row.py" "$glint" "$file" "$ref" "$results/$name-cycles-$stamp" --size "$size" \
    --times "$times" --seeds "${SEEDS:-2}" --threads "$(nproc)" "$@"
}

have_scene() { case "$1" in builtin:*) ;; *) [ -f "$1" ] || { echo "skipping $1: not found"; return 1; } ;; esac; }

if [ "$mode" = vsl ]; then
  echo "## The VSL paper's comparisons, default scene ($(nproc) threads, $(date +%F))"
  ref=$(reference atelier builtin:atelier)
  bench atelier builtin:atelier "$ref" vsl-paper
  bench atelier builtin:atelier "$ref" fig8
  exit 0
fi

if [ "$mode" = hl ]; then
  echo "## The highlight paper's comparison, default scene ($(nproc) threads, $(date +%F))"
  hl_seconds=${HL_REF_SECONDS:-600}
  ref=$cache/atelier-$size-hl-trace${hl_seconds}s-$model.exr
  if [ ! -f "$ref" ]; then
    echo "rendering the highlights reference (--merge trace, 64 secondary rays) for $hl_seconds s"
    "$glint" render builtin:atelier --method vsl+hl --merge trace --secondary-rays 64 --time "$hl_seconds" \
      --size "$size" --seed 777 --out "$ref" --quiet
  fi
  bench atelier builtin:atelier "$ref" highlights
  bench atelier builtin:atelier "$ref" highlights-whole
  exit 0
fi

if [ "$mode" = bench ]; then
  for entry in builtin:atelier:atelier builtin:doorway:doorway builtin:showcase:showcase "$cornell:cornell"; do
    file=${entry%:*}
    name=${entry##*:}
    have_scene "$file" || continue
    ref=$(reference "$name" "$file")
    if [ -n "${LONG_SECONDS:-}" ]; then
      bench "$name" "$file" "$ref" headline --times "${TIMES:-2,10,60},$LONG_SECONDS"
    else
      bench "$name" "$file" "$ref" headline
    fi
    cycles "$name" "$file" "$ref" "${TIMES:-2,10,60}${LONG_SECONDS:+,$LONG_SECONDS}"
  done
  bench showcase builtin:showcase "$(reference showcase builtin:showcase)" fig8
  exit 0
fi

if [ "$mode" = suite ]; then
  echo "## Where each method wins: the suite ($(nproc) threads, $(date +%F))"
  lamp=$scenes/lights-punctual-lamp/glTF/LightsPunctualLamp.gltf
  helmet=$scenes/damaged-helmet/glTF/DamagedHelmet.gltf
  sunset=$scenes/envmaps/venice_sunset_1k.hdr
  for entry in builtin:atelier:atelier builtin:doorway:doorway builtin:showcase:showcase builtin:bay:bay \
    "$cornell:cornell" "$lamp:lamp" "$helmet:helmet"; do
    file=${entry%:*}
    name=${entry##*:}
    have_scene "$file" || continue
    env=()
    if [ "$name" = helmet ]; then
      [ -f "$sunset" ] || { echo "skipping $file: $sunset not found"; continue; }
      env=(--env "$sunset")
      name=helmet-sunset
    fi
    ref=$(reference "$name" "$file" "${env[@]}")
    bench "$name" "$file" "$ref" headline --times "${TIMES:-10,60}" "${env[@]}"
    cycles "$name" "$file" "$ref" "${TIMES:-10,60}" "${env[@]}"
  done
  exit 0
fi

if [ "$mode" = plan ]; then
  echo "## The effect plan's saving ($(nproc) threads, $(date +%F))"
  for entry in builtin:atelier:atelier "$cornell:cornell"; do
    file=${entry%:*}
    name=${entry##*:}
    have_scene "$file" || continue
    bench "$name" "$file" "$(reference "$name" "$file")" plan
  done
  exit 0
fi

seconds_of() { # wall seconds of a command, its output discarded
  local t0 t1
  t0=$(date +%s.%N)
  "$@" >/dev/null 2>&1
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }'
}
json_seconds() { sed -n 's/^ *"seconds": \([0-9.]*\),$/\1/p' "$1"; }

tp_size=${TP_SIZE:-640x360}
tp_spp=${TP_SPP:-32}
tp_depth=${TP_DEPTH:-8}
w=${tp_size%x*}
h=${tp_size#*x}
command -v pathtracer >/dev/null || { echo "pathtracer (embree-tools) not installed"; exit 1; }
echo "## Path-tracing throughput ($tp_size, $tp_spp spp, path length $tp_depth, $(nproc) threads, best of ${TP_RUNS:-3} alternating runs)"
printf '| scene | glint samples/s | Embree pathtracer samples/s | ratio |\n|---|---|---|---|\n'
for s in cornell-box/CornellBox-Original.gltf lights-punctual-lamp/glTF/LightsPunctualLamp.gltf; do
  [ -f "$scenes/$s" ] || { echo "skipping $s: not found"; continue; }
  "$glint" info "$scenes/$s" --obj "$work/geometry.obj" >/dev/null
  light=$(python3 "$root/tests/bench/embree_twin.py" scene "$scenes/$s" "$work/geometry.obj" "$work/lambert.gltf")
  "$glint" info "$work/lambert.gltf" --obj "$work/lambert.obj" >/dev/null
  render=("$glint" render "$work/lambert.gltf" --size "$tp_size" --max-depth "$tp_depth" --seed 1 --quiet)
  "${render[@]}" --spp 1 --stats "$work/one.json"
  read -r -a args <<<"-i $work/lambert.obj --size $w $h --max-path-length $tp_depth \
    $(python3 "$root/tests/bench/embree_twin.py" camera "$work/one.json") $light --threads $(nproc)"
  best_g=0 best_e=0
  for run in $(seq "${TP_RUNS:-3}"); do # alternate the two so both see the same machine load
    # Each renders tp_spp samples and 1; the difference leaves out loading, the BVH and warm-up.
    "${render[@]}" --spp "$tp_spp" --stats "$work/full.json"
    "${render[@]}" --spp 1 --stats "$work/one.json"
    g=$(awk -v full="$(json_seconds "$work/full.json")" -v one="$(json_seconds "$work/one.json")" \
      -v n="$((w * h * (tp_spp - 1)))" 'BEGIN { printf "%.0f", n / (full - one) }')
    t_full=$(seconds_of pathtracer "${args[@]}" --spp "$tp_spp" -o "$work/embree.ppm")
    t_one=$(seconds_of pathtracer "${args[@]}" --spp 1 -o "$work/embree1.ppm")
    e=$(awk -v full="$t_full" -v one="$t_one" -v n="$((w * h * (tp_spp - 1)))" 'BEGIN { printf "%.0f", n / (full - one) }')
    best_g=$(awk -v a="$best_g" -v b="$g" 'BEGIN { print (b > a ? b : a) }')
    best_e=$(awk -v a="$best_e" -v b="$e" 'BEGIN { print (b > a ? b : a) }')
  done
  awk -v s="$s" -v g="$best_g" -v e="$best_e" 'BEGIN { printf "| %s | %.0f | %.0f | %.2f |\n", s, g, e, g / e }'
done

echo
echo "## Load + BVH build, 1.04 M triangles"
grid=$scenes/metal-rough-spheres-notextures/glTF/MetalRoughSpheresNoTextures.gltf
if [ -f "$grid" ]; then
  "$glint" info "$grid" | grep -E 'geometry|load'
else
  echo "skipping: $grid not found"
fi
