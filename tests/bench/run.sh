#!/usr/bin/env bash
# glint benchmarks (release build; numbers are ratios measured in one run on a shared machine).
#   1. Path-tracing throughput against Embree's own `pathtracer` (embree-tools) on the same
#      triangles, camera, point light, size, spp and path length.
#   2. Load + BVH build time and peak memory for the 1.04 M-triangle sphere grid.
#   3. With `vsl` first: the VSL paper's comparisons on the default scene (bench_vsl: equal-time
#      error of pt, vpl and vsl against a 20-minute path-traced reference, cached in
#      build/bench-cache; pt and vsl again over 4 seeds, the aim's table; the Fig. 8 sweeps),
#      about 18 minutes plus the reference.
#   4. With `hl` first: the highlight paper's comparison on the default scene (bench_hl: the
#      highlight component alone at equal time, path tracing its paths vs no merging vs merging
#      into K lobes, N secondary rays, against a 10-minute reference cached in build/bench-cache;
#      and the share of time spent merging; for N = 8 the error split into noise and bias by two
#      independent runs; then the whole renderer at equal time, the path tracer's highlights layer
#      against vsl+hl's), about 16 minutes plus the reference.
#   5. With `bench` first: `glint bench`, the headline comparison: pt, vsl and vsl+hl, 2 seeds,
#      at 2, 10 and 60 s (LONG_SECONDS adds a longer budget), on builtin:atelier, doorway and
#      showcase and the shared Cornell box at 320x240, each against a path-traced reference with
#      its highlights layer, rendered once into build/bench-cache (REF_SECONDS, default 1200);
#      then the Fig. 8 sweeps on showcase. About 8 minutes a scene plus the references; results
#      (CSV, plots, report.md) go to build/bench-results/.
#   6. With `plan` first: what the effect plan saves (bench_plan: vsl+hl with the plan and with
#      every pass forced on, 30 s each) on the default scene and the shared Cornell box, against
#      the path-traced references of mode 3 (rendered here when missing), about 2 minutes.
# Usage: tests/bench/run.sh [vsl|hl|bench|plan] [SHARED_SCENES_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
mode=pt
case "${1:-}" in vsl | hl | bench | plan) mode=$1; shift ;; esac
scenes=${1:-$root/../shared/scenes}
build=$root/build
source "$root/scripts/deps.sh"
glint_install_deps
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DGLINT_TESTS=OFF >/dev/null
cmake --build "$build" -j"$(nproc)" >/dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

if [ "$mode" = vsl ]; then
  mkdir -p "$build/bench-cache"
  echo "## The VSL paper's comparisons, default scene ($(nproc) threads, $(date +%F))"
  "$build/tests/bench/bench_vsl" default "$build/bench-cache/default-320x180-pt1200s.exr" 320x180 1200 10,60 10
  exit 0
fi

if [ "$mode" = bench ]; then
  # The headline: pt, vsl and vsl+hl at equal time against a long path-traced reference (with
  # its highlights layer, so the highlight estimator's share compares too), 2 seeds, at 2, 10 and
  # 60 s, on the indirect-lit rooms, the former default and the shared Cornell box. Set
  # LONG_SECONDS (e.g. 300) to add that budget for the slope past 5 minutes.
  glint=$build/app/glint
  mkdir -p "$build/bench-cache" "$build/bench-results"
  stamp=$(date +%Y%m%d-%H%M%S)
  times=2,10,60${LONG_SECONDS:+,$LONG_SECONDS}
  for entry in builtin:atelier:atelier builtin:doorway:doorway builtin:showcase:showcase \
               "$scenes/cornell-box/CornellBox-Original.gltf:cornell"; do
    file=${entry%:*}
    name=${entry##*:}
    case "$file" in builtin:*) ;; *) [ -f "$file" ] || { echo "skipping $file: not found"; continue; } ;; esac
    ref=$build/bench-cache/$name-320x240-pt-ref.exr
    if [ ! -f "$ref.json" ]; then
      echo "rendering the path-traced reference of $name for ${REF_SECONDS:-1200} s"
      "$glint" render "$file" --method pt --time "${REF_SECONDS:-1200}" --size 320x240 --seed 777 \
        --highlights-layer --out "$ref" --quiet
    fi
    "$glint" bench "$file" --reference "$ref" --methods pt,vsl,vsl+hl --seeds 2 --times "$times" \
      --out "$build/bench-results/$name-$stamp" --quiet
    cat "$build/bench-results/$name-$stamp/report.md"
  done
  # Fig. 8: the paper's estimator (every lobe gathered), 4096 lights a frame, both sweeps in one run.
  "$glint" bench builtin:showcase --reference "$build/bench-cache/showcase-320x240-pt-ref.exr" \
    --methods vsl --trace-glossy off --vsl-count 4096 --times 5,10 \
    --sweep radius-mult=1,2,4,8,12,16,24 --sweep columns=64,128,256,512,1024 \
    --out "$build/bench-results/fig8-$stamp" --quiet
  cat "$build/bench-results/fig8-$stamp/report.md"
  exit 0
fi

if [ "$mode" = plan ]; then
  mkdir -p "$build/bench-cache"
  echo "## The effect plan's saving ($(nproc) threads, $(date +%F))"
  "$build/tests/bench/bench_plan" default "$build/bench-cache/default-320x180-pt1200s.exr" 320x180 1200 30
  cornell=$scenes/cornell-box/CornellBox-Original.gltf
  if [ -f "$cornell" ]; then
    "$build/tests/bench/bench_plan" "$cornell" "$build/bench-cache/cornell-320x320-pt600s.exr" 320x320 600 30 | tail -n 2
  else
    echo "skipping $cornell: not found"
  fi
  exit 0
fi

if [ "$mode" = hl ]; then
  mkdir -p "$build/bench-cache"
  echo "## The highlight paper's comparison, default scene ($(nproc) threads, $(date +%F))"
  "$build/tests/bench/bench_hl" default "$build/bench-cache/default-320x180-hl-trace600s.exr" 320x180 600 30
  exit 0
fi

seconds_of() { # wall seconds of a command, its output discarded
  local t0 t1
  t0=$(date +%s.%N)
  "$@" >/dev/null 2>&1
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }'
}

echo "## Path-tracing throughput (640x360, 32 spp, path length 8, $(nproc) threads, best of 3 alternating runs)"
printf '| scene | glint samples/s | Embree pathtracer samples/s | ratio |\n|---|---|---|---|\n'
for s in cornell-box/CornellBox-Original.gltf lights-punctual-lamp/glTF/LightsPunctualLamp.gltf; do
  [ -f "$scenes/$s" ] || { echo "skipping $s: not found"; continue; }
  best_g=0 best_e=0
  for run in 1 2 3; do # alternate the two so both see the same machine load
    out=$("$build/tests/bench/bench_pt" "$scenes/$s" "$work" 640 360 32 8)
    g=$(sed -n 's/^glint_samples_per_second: //p' <<<"$out")
    read -r -a args <<<"$(sed -n 's/^embree_args: //p' <<<"$out")"
    # Embree renders one frame of --spp samples; subtract a 1-spp run to remove load and BVH time.
    one=("${args[@]}")
    for i in "${!one[@]}"; do [ "${one[$i]}" = "--spp" ] && one[$((i + 1))]=1; done
    t_full=$(seconds_of pathtracer "${args[@]}" --threads "$(nproc)" -o "$work/embree.ppm")
    t_one=$(seconds_of pathtracer "${one[@]}" --threads "$(nproc)" -o "$work/embree1.ppm")
    e=$(awk -v full="$t_full" -v one="$t_one" 'BEGIN { printf "%.0f", 640 * 360 * 31 / (full - one) }')
    best_g=$(awk -v a="$best_g" -v b="$g" 'BEGIN { print (b > a ? b : a) }')
    best_e=$(awk -v a="$best_e" -v b="$e" 'BEGIN { print (b > a ? b : a) }')
  done
  awk -v s="$s" -v g="$best_g" -v e="$best_e" 'BEGIN { printf "| %s | %.0f | %.0f | %.2f |\n", s, g, e, g / e }'
done

echo
echo "## Load + BVH build, 1.04 M triangles"
grid=$scenes/metal-rough-spheres-notextures/glTF/MetalRoughSpheresNoTextures.gltf
if [ -f "$grid" ]; then
  "$build/app/glint" info "$grid" | grep -E 'geometry|load'
else
  echo "skipping: $grid not found"
fi
