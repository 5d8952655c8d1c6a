#!/bin/sh
# The viewer while the camera moves, on the default scene at 960x540 under Xvfb, for each method:
# - the first image after a camera step: 5 scripted orbit steps of 5 degrees, each while a
#   full-resolution frame is in flight, timed by the viewer from the step to the image it takes
#   (the stats' step_ms);
# - updates a second while orbiting continuously (a scripted drag, a little every drawn frame) for
#   SECONDS, and the size of the images shown meanwhile;
# - quitting: from an Escape key press (xdotool) while a full-resolution frame is in flight to the
#   process's exit, timed from outside.
# A measurement, not a test: the issue's aims are 100 ms, 10 updates a second and 100 ms on 2 cores.
# Use a release build.
# Usage: tests/bench/viewer_motion.sh [GLINT [SECONDS [METHODS]]]
#        (default: build/app/glint, 10, "pt vpl vsl vsl+hl")
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
glint=${1:-$root/build/app/glint}
seconds=${2:-10}
methods=${3:-pt vpl vsl vsl+hl}
[ -x "$glint" ] || { echo "no glint at $glint (build it: tests/bench/run.sh builds build/)"; exit 1; }
glint=$(cd "$(dirname "$glint")" && pwd)/$(basename "$glint") # the viewer runs in a scratch directory
command -v xdotool >/dev/null || { echo "xdotool not installed"; exit 1; }
work=$(mktemp -d)
. "$root/tests/bench/xvfb.sh"
xvfb_remove_dir=1
xvfb_start "$work" || exit 1
cd "$work"
{
  echo "sleep 3"
  for i in 1 2 3 4 5; do printf 'orbit 5 0\nsleep 1.5\nstats\n'; done
  printf 'stats\nspin 36 %s\nstats\nsleep 2\nstats\nsleep 600\nquit\n' "$seconds"
} >motion.txt
now() { date +%s.%N; }
echo "viewer motion, default scene 960x540, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg):"
for method in $methods; do
  rm -f out.txt
  "$glint" --size 960x540 --method "$method" --script motion.txt >out.txt 2>err.txt &
  viewer=$!
  # the eighth stats line comes 2 s after the orbit, a full frame in flight: then Escape
  until [ "$(cat out.txt 2>/dev/null | grep -c '^stats ')" -ge 8 ]; do
    kill -0 $viewer 2>/dev/null || { echo "viewer failed: $(cat err.txt)"; exit 1; }
    sleep 0.05
  done
  window=$(xdotool search --onlyvisible --name glint | head -n 1)
  xdotool windowfocus --sync "$window" 2>/dev/null || true
  t0=$(now)
  xdotool key Escape
  t1=$(now)
  wait $viewer || { echo "viewer failed: $(cat err.txt)"; exit 1; }
  t2=$(now)
  quit=$(awk -v a="$t0" -v b="$t1" -v c="$t2" 'BEGIN { printf "%.0f ms (xdotool itself %.0f ms)", 1e3 * (c - a), 1e3 * (b - a) }')
  grep '^stats ' out.txt | awk -v s="$seconds" -v m="$method" -v quit="$quit" '
    {
      n++
      for (i = 2; i <= NF; i++) { split($i, kv, "="); f[n, kv[1]] = kv[2] }
    }
    END {
      for (i = 1; i <= 5; i++) step[i] = f[i, "step_ms"]
      for (i = 1; i <= 5; i++) for (j = i + 1; j <= 5; j++) if (step[j] < step[i]) { t = step[i]; step[i] = step[j]; step[j] = t }
      frames = f[7, "images"] - f[6, "images"]; dt = f[7, "time"] - f[6, "time"]
      printf "  %-7s first image after a step: median %.0f ms, max %.0f ms (5 steps); orbiting: %.1f updates/s (%d images in %.1f s, the last %sx%s); from Escape to the exit: %s\n",
             m, step[3], step[5], frames / dt, frames, dt, f[7, "width"], f[7, "height"], quit
    }'
done
