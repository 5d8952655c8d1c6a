#!/bin/sh
# Updates per second while the camera moves: the viewer on the default scene at 960x540 under
# Xvfb, orbiting continuously (a scripted drag, a little every drawn frame) for SECONDS; every
# image it shows meanwhile is a reduced-resolution preview frame (a third of the size or less:
# the viewer coarsens previews whose frames are slow). A measurement, not a test: the issue's aim
# is 10 updates a second on 2 cores. Use a release build.
# Usage: tests/bench/viewer_motion.sh [GLINT [SECONDS [METHOD]]]   (default: build/app/glint, 10, pt)
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
glint=${1:-$root/build/app/glint}
seconds=${2:-10}
method=${3:-pt}
[ -x "$glint" ] || { echo "no glint at $glint (build it: tests/bench/run.sh builds build/)"; exit 1; }
glint=$(cd "$(dirname "$glint")" && pwd)/$(basename "$glint") # the viewer runs in a scratch directory
command -v Xvfb >/dev/null || { echo "Xvfb not installed"; exit 1; }
work=$(mktemp -d)
Xvfb -displayfd 3 -screen 0 1280x800x24 -nolisten tcp 3>"$work/display.txt" 2>"$work/xvfb.log" &
xvfb=$!
trap 'kill $xvfb 2>/dev/null; wait $xvfb 2>/dev/null; rm -rf "$work"' EXIT
tries=0
until [ -s "$work/display.txt" ]; do
  tries=$((tries + 1))
  [ $tries -le 300 ] || { echo "Xvfb did not start"; exit 1; }
  sleep 0.1
done
export DISPLAY=":$(head -n 1 "$work/display.txt")"
printf 'wait 2\nstats\nspin 36 %s\nstats\nquit\n' "$seconds" >"$work/motion.txt"
(cd "$work" && "$glint" --size 960x540 --method "$method" --script motion.txt >out.txt 2>err.txt) ||
  { echo "viewer failed: $(cat "$work/err.txt")"; exit 1; }
grep '^stats ' "$work/out.txt" | tr ' ' '\n' | awk -F= -v s="$seconds" -v m="$method" -v cores="$(nproc)" '
  $1 == "preview_frames" { pf[++n] = $2 }
  $1 == "time" { t[n] = $2 }
  $1 == "preview_size" { size = $2 }
  END {
    frames = pf[2] - pf[1]; dt = t[2] - t[1]
    printf "viewer motion, default scene 960x540, method %s, %d cores: %d preview frames (last %s) in %.1f s of orbiting: %.1f updates/s\n",
           m, cores, frames, size, dt, frames / dt
  }'
