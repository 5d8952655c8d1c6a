#!/usr/bin/env bash
# What the viewer shows, measured: the displayed image's relative L2 error against path-traced
# references of exactly the poses shown, during and after motion. It drives the real window
# through the script language (capture, stats), so it measures any viewer that speaks it.
#
# For each scene (builtin:NAME) and method, at 960x540 under Xvfb (1920x1080), three sessions:
#   orbit  sleep 10 and a capture (opened-10.exr: 10 s at rest, the moonshot's plain
#          accumulation); 10 x (orbit 1.5 0; sleep 0.1), 15 degrees at 15 degrees a second, capturing
#          at the end of steps 3, 6 and 9, just before the next (during-3/6/9.exr: what the step
#          left on screen, measured at its own pose), and stats before and after the orbit (updates
#          a second, those at full resolution, their mean size); then captures 0.25, 1, 3, 5 and
#          10 s after the last step (after-T.exr); window shots (panel included, for the docs)
#          during the orbit (after step 9) and 1 s after it (window-during.png, window-after-1.png).
#   jump   sleep 4; set camera 1 (the scene's second glTF camera); captures 0.25, 1, 3, 5, 10 s on.
#   rate   the orbit again (sleep 10, its 10 steps, stats before and after), with no capture or
#          window shot: each capture writes an EXR on the window's thread, on the renderer's two
#          cores (the orbit session made 6 updates in 1.1 s where this one made 8 to 9); the
#          updates a second a person gets.
#   light  sleep 10; light 0 dragged across its room in 10 steps over 1 s (move-light 0 DX DY DZ;
#          sleep 0.1); captures 0.25, 1 and 3 s after. atelier: the torchiere's spot from the
#          back-left corner (-2.4, 1.89, -1.7) 4.8 m along +x to the back-right (2.4, 1.89, -1.7);
#          doorway: the spot in the back room (1.45, 2.15, -1.55) 3.3 m along -x to its left side
#          (-1.85, 2.15, -1.55), out of line with the doorway. Both stay inside their rooms.
# Each capture records the camera and lights of the image it shows (glint view's `capture`); the
# references are `glint render --method pt --camera-from CAPTURE [--move-light ...]` of each
# distinct pose, in shards merged by glint merge, cached in the refs directory by pose (a pose
# within the viewer's camera tolerance of a cached one reuses it: viewer_display.py).
#
# Phases (--phase, default all):
#   captures  the viewer sessions; captures in OUT/SCENE/METHOD/SCENARIO/ (with the viewer's
#             stdout, stderr and script), replacing those of an earlier run of the same ones
#   refs      the missing references, --ref-spp-rest frames for poses after a stop and
#             --ref-spp-motion for poses during the orbit, seed 777, --ref-shards shards each:
#             finished shards are kept, so an interrupted run resumes; REFS/poses.md lists the poses
#   compare   glint compare of every capture with its pose's reference: OUT/results.md and .csv
#             (scene, method, scenario, time after the stop or "during", the net error with the
#             reference's noise taken out, that noise, and for the orbit the updates a second)
#   all       the three in turn
# Usage: tests/bench/viewer_display.sh [--phase P] [--scenes "atelier doorway"]
#          [--methods "vsl vsl+hl"] [--out DIR] [--refs DIR] [--ref-spp-rest 2048]
#          [--ref-spp-motion 256] [--ref-shards 8] [--glint build/app/glint]
# (add pt to --methods as a comparison; SCENARIOS="orbit light" in the environment runs only those
# of orbit, rate, jump and light). A measurement, not a test: use a release build on an otherwise idle
# machine; the issue's aims are in docs/benchmarks.md.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
phase=all scenes="atelier doorway" methods="vsl vsl+hl" size=960x540
out=$root/build/viewer-display refs=$root/build/viewer-display-refs
spp_rest=2048 spp_motion=256 shards=8 glint=$root/build/app/glint
while [ $# -gt 0 ]; do
  case $1 in
  --phase) phase=$2 ;;
  --scenes) scenes=$2 ;;
  --methods) methods=$2 ;;
  --out) out=$2 ;;
  --refs) refs=$2 ;;
  --ref-spp-rest) spp_rest=$2 ;;
  --ref-spp-motion) spp_motion=$2 ;;
  --ref-shards) shards=$2 ;;
  --glint) glint=$2 ;;
  *) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 2 ;;
  esac
  shift 2
done
case $phase in captures | refs | compare | all) ;; *) echo "--phase: captures, refs, compare or all"; exit 2 ;; esac
[ -x "$glint" ] || { echo "no glint at $glint (build the release: see docs/benchmarks.md)"; exit 1; }
glint=$(cd "$(dirname "$glint")" && pwd)/$(basename "$glint")
mkdir -p "$out" "$refs"
out=$(cd "$out" && pwd) refs=$(cd "$refs" && pwd)
helper=$root/tests/bench/viewer_display.py

# light_step SCENE: one of the ten steps of the light's drag (a tenth of the offset above).
light_step() {
  case $1 in
  atelier) echo "0.48 0 0" ;;
  doorway) echo "-0.33 0 0" ;;
  *) echo "no light drag for $1 (atelier, doorway)" >&2; return 1 ;;
  esac
}

# rest_captures T...: sleeps to each T seconds after the last change and captures there.
rest_captures() {
  local at=0 t
  for t in "$@"; do
    echo "sleep $(awk -v a="$at" -v b="$t" 'BEGIN { print b - a }')"
    echo "capture after-$t.exr"
    [ "$t" != 1 ] || [ "${shots:-}" != 1 ] || echo "window-shot window-after-1.png"
    at=$t
  done
}

# script SCENARIO SCENE: the viewer's script for one session.
script() {
  case $1 in
  orbit)
    echo "sleep 10"
    echo "capture opened-10.exr"
    echo "stats"
    for i in 1 2 3 4 5 6 7 8 9 10; do
      echo "orbit 1.5 0"
      [ $i = 10 ] || echo "sleep 0.1"
      case $i in 3 | 6 | 9) echo "capture during-$i.exr" ;; esac # what step i left on screen
      [ $i != 9 ] || echo "window-shot window-during.png"
    done
    echo "stats"
    shots=1 rest_captures 0.25 1 3 5 10
    ;;
  rate)
    printf 'sleep 10\nstats\n'
    for i in 1 2 3 4 5 6 7 8 9 10; do
      echo "orbit 1.5 0"
      [ $i = 10 ] || echo "sleep 0.1"
    done
    echo "stats"
    ;;
  jump)
    printf 'sleep 4\nset camera 1\n'
    rest_captures 0.25 1 3 5 10
    ;;
  light)
    local step
    step=$(light_step "$2")
    echo "sleep 10"
    for i in 1 2 3 4 5 6 7 8 9 10; do
      echo "move-light 0 $step"
      [ $i = 10 ] || echo "sleep 0.1"
    done
    rest_captures 0.25 1 3
    ;;
  esac
  echo "stats"
  echo "quit"
}

run_captures() {
  local work scene method scenario dir
  work=$(mktemp -d)
  . "$root/tests/bench/xvfb.sh"
  xvfb_remove_dir=1
  xvfb_start "$work" || exit 1
  echo "captures: $size, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), into $out"
  for scene in $scenes; do
    for method in $methods; do
      for scenario in ${SCENARIOS:-orbit rate jump light}; do
        dir=$out/$scene/$method/$scenario
        rm -rf "$dir"
        mkdir -p "$dir"
        script $scenario "$scene" >"$dir/script.txt"
        (cd "$dir" && timeout 300 "$glint" view "builtin:$scene" --size $size --method "$method" \
          --script script.txt >stdout.txt 2>stderr.txt) ||
          { echo "$scene $method $scenario: the viewer failed: $(tail -n 3 "$dir/stderr.txt")"; exit 1; }
        cut -d' ' -f1-3 /proc/loadavg >"$dir/load.txt" # a busy machine slows the viewer: say how busy
        echo "  $scene $method $scenario: $(grep -c '^glint: wrote .*\.exr' "$dir/stdout.txt") captures, load $(cat "$dir/load.txt")"
      done
    done
  done
}

# The missing references, each as shards (kept when finished) merged into one file.
run_refs() {
  local list ref spp capture scene wh i shard parts
  list=$(python3 "$helper" poses "$out" "$refs" "$spp_rest" "$spp_motion")
  echo "poses: $refs/poses.md; references to render: $(printf '%s' "$list" | grep -c . || true)"
  [ -n "$list" ] || return 0
  while IFS=$'\t' read -r -a f; do
    ref=${f[0]} spp=${f[1]} capture=${f[2]} scene=${f[3]} wh=${f[4]}
    parts=()
    for ((i = 0; i < shards; i++)); do
      shard=${ref%.exr}.shard-$i-of-$shards.exr
      parts+=("$shard")
      [ -f "$shard" ] && continue # written atomically: there means finished
      echo "  $(basename "$ref"): shard $i of $shards, $spp spp in all"
      "$glint" render "$scene" --method pt --camera-from "$capture" "${f[@]:5}" --size "$wh" --spp "$spp" \
        --seed 777 --shard "$i/$shards" --out "$shard" --quiet
    done
    "$glint" merge "${parts[@]}" --out "$ref" >/dev/null
    rm -f "${parts[@]}"
    echo "  wrote $ref"
  done <<<"$list"
}

run_compare() {
  python3 "$helper" poses "$out" "$refs" "$spp_rest" "$spp_motion" >/dev/null
  python3 "$helper" table "$out" "$refs" "$glint" "$out/results"
  cat "$out/results.md"
  echo "(also $out/results.csv)"
}

case $phase in
captures) run_captures ;;
refs) run_refs ;;
compare) run_compare ;;
all) run_captures && run_refs && run_compare ;;
esac
