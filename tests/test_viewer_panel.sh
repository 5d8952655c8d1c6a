#!/bin/sh
# The viewer's panel and overlay under Xvfb, read from its own screenshots: the panel docks beside
# the image (the window's image region matches the render pixel for pixel at the centre, at 960x540
# and 480x270) and stays on-screen after resizes; the overlay writes in the image's corner; F1
# shows the key list; pause stops the frame count and --spp stops it at N; a preview while moving
# is magnified smoothly, not in blocks. Through --script, and the keys and resizes also through
# real X events (xdotool).
# Usage: test_viewer_panel.sh GLINT TMPDIR KEEP_MODULES_LIB PNG_PROBE
set -u
glint=$1
dir=$2/viewer_panel
keep_modules=$3
probe=$4
# A screen wide enough for a 960x540 image beside the panel.
screen=1920x1080x24
. "$(dirname "$0")/viewer_harness.sh"
probe() { "$probe" "$@" || echo 999999; }

# ---- the panel beside the image, the overlay, the help ----------------------------------------
cat >docked.txt <<'EOF'
wait 1
pause
sleep 0.2
stats
screenshot image.png
window-shot window.png
key f1
sleep 0.2
window-shot help.png
key f1
quit
EOF
for size in 960x540 480x270; do
  w=${size%x*} h=${size#*x}
  rm -f image.png window.png help.png
  view --size "$size" --script docked.txt
  rc=$?
  [ $rc -eq 0 ] || fail "$size: exited $rc: $(cat err.txt)"
  grep '^stats ' out.txt >stats.txt
  [ "$(field 1 image)" = "$size" ] || fail "$size: the image beside the panel is $(field 1 image)"
  [ "$(field 1 width)x$(field 1 height)" = "$size" ] || fail "$size: renders $(field 1 width)x$(field 1 height)"
  dock=$(field 1 dock)
  [ "$dock" -gt 0 ] || fail "$size: no docked panel"
  [ "$(field 1 window)" = "$((w + dock))x$h" ] || fail "$size: window $(field 1 window), panel $dock"
  # The window shows the render itself at the image's centre: the panel covers none of it.
  cx=$((w / 2)) cy=$((h / 2)) r=$((h / 8))
  d=$(probe window.png diff image.png $((cx - r)) $((cy - r)) $((cx + r)) $((cy + r)))
  awk -v d="$d" 'BEGIN { exit !(d < 3) }' || fail "$size: the image centre differs from the render by $d"
  # The panel is drawn to the window's right of the image, and holds text.
  [ "$(probe window.png size)" = "$((w + dock)) $h" ] || fail "$size: window shot $(probe window.png size)"
  [ "$(probe window.png ink "$w" 0 $((w + dock)) "$h")" -ge 10 ] || fail "$size: no panel text"
  # The overlay writes in the image's top-left corner: there the window is not the render.
  d=$(probe window.png diff image.png 0 0 200 40)
  awk -v d="$d" 'BEGIN { exit !(d > 15) }' || fail "$size: no overlay in the corner (differs by $d)"
  # F1 lists the keys over the image's centre (paused: the image itself stands still).
  d=$(probe help.png diff window.png $((cx - 100)) $((cy - 40)) $((cx + 100)) $((cy + 40)))
  awk -v d="$d" 'BEGIN { exit !(d > 15) }' || fail "$size: F1 showed no key list (differs by $d)"
  cp window.png "window-$size.png"
  cp help.png "help-$size.png"
done

# ---- pause, resume, and the limits ------------------------------------------------------------
cat >pause.txt <<'EOF'
wait 1
pause
sleep 0.5
stats
sleep 1
stats
resume
wait 2
stats
set spp 2
sleep 1
stats
set spp 0
key space
sleep 0.5
stats
sleep 1
stats
quit
EOF
view --size 160x90 --script pause.txt
rc=$?
[ $rc -eq 0 ] || fail "pause script exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(field 1 paused)" = 1 ] && [ "$(field 1 held)" = 1 ] || fail "pause not taken: $(sed -n 1p stats.txt)"
[ "$(field 2 frames)" = "$(field 1 frames)" ] || fail "frames went on while paused: $(field 1 frames) -> $(field 2 frames)"
[ "$(field 3 frames)" -ge $(($(field 2 frames) + 2)) ] || fail "resume did not refine: $(field 3 frames)"
[ "$(field 4 spp_limit)" = 2 ] && [ "$(field 4 held)" = 1 ] || fail "set spp below the frames did not hold"
[ "$(field 5 paused)" = 1 ] || fail "Space did not pause"
[ "$(field 6 frames)" = "$(field 5 frames)" ] || fail "frames went on after Space: $(field 5 frames) -> $(field 6 frames)"

cat >limit.txt <<'EOF'
wait 3
sleep 1.5
stats
quit
EOF
view --size 160x90 --spp 3 --script limit.txt
rc=$?
[ $rc -eq 0 ] || fail "--spp 3 exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(field 1 frames)" = 3 ] && [ "$(field 1 held)" = 1 ] || fail "--spp 3 did not stop at 3: $(field 1 frames)"
view --size 160x90 --time 1 --script limit.txt
grep '^stats ' out.txt >stats.txt
[ "$(field 1 time_limit)" = 1 ] && [ "$(field 1 held)" = 1 ] || fail "--time 1 did not stop: $(cat stats.txt)"
view --size 160x90 --spp 0 --script limit.txt && fail "--spp 0 accepted"
view view --help
grep -q 'F1 or ?' out.txt && grep -q -- '--spp N' out.txt || fail "--help lacks the key list or --spp"

# ---- previews magnified smoothly ----------------------------------------------------------------
rm -f preview.png
cat >preview.txt <<'EOF'
wait 1
spin 90 1.5
stats
window-shot preview.png
quit
EOF
view --size 480x270 --script preview.txt
rc=$?
[ $rc -eq 0 ] || fail "preview script exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
if [ "$(field 1 preview)" = 1 ]; then
  b=$(probe preview.png blocky 0 60 480 270)
  [ "$b" -le 5 ] || fail "the preview ($(field 1 preview_size)) is blocky: $b per mille of 3x3 windows flat"
else
  echo "no preview frame on screen after the spin: blockiness not checked"
fi

# ---- real X events: resizes keep the panel on-screen, its edge drags, F1 and Space -------------
if command -v xdotool >/dev/null; then
  cat >xevents.txt <<'EOF'
wait 1
set exposure -30
screenshot ready.png
sleep 7
stats
window-shot resized.png
quit
EOF
  view --size 480x270 --script xevents.txt &
  viewer=$!
  tries=0
  until [ -s ready.png ] || [ $tries -gt 600 ]; do tries=$((tries + 1)); sleep 0.1; done
  win=$(xdotool search --name 'glint' | head -n 1)
  if [ -n "$win" ]; then
    xdotool windowsize "$win" 200 120
    sleep 0.5
    xdotool windowsize "$win" 700 300
    sleep 0.5
    # Drag the panel's left edge 40 to the left: it widens from its default 360.
    xdotool mousemove --window "$win" 341 150 sleep 0.2 mousedown 1 sleep 0.1
    for x in 331 321 311 301; do xdotool mousemove --window "$win" $x 150 sleep 0.1; done
    xdotool mouseup 1
    sleep 0.5
    xdotool windowfocus "$win" 2>/dev/null
    xdotool key F1
    xdotool key space
  else
    fail "xdotool found no viewer window"
  fi
  wait $viewer
  rc=$?
  [ $rc -eq 0 ] || fail "X events session exited $rc: $(cat err.txt)"
  grep '^stats ' out.txt >stats.txt
  [ "$(field 1 window)" = 700x300 ] || fail "the window was not resized: $(field 1 window)"
  dock=$(field 1 dock)
  [ "$dock" -gt 0 ] && [ "$dock" -le 420 ] || fail "after resizes the panel is $dock wide in 700"
  [ "$dock" -ge 390 ] || fail "dragging its edge did not widen the panel: $dock"
  [ "$(field 1 image)" = "$((700 - dock))x300" ] || fail "image $(field 1 image) beside a $dock panel"
  [ "$(probe resized.png ink $((700 - dock)) 0 700 300)" -ge 10 ] || fail "no panel on-screen after resizes"
  [ "$(field 1 help)" = 1 ] || fail "the F1 key did not show the help"
  [ "$(field 1 paused)" = 1 ] || fail "the Space key did not pause"
  cx=$(((700 - dock) / 2))
  # The list's text over the image (shown black: exposure -30, so a noisy render has no ink; the
  # panel, right of it, has ink of its own).
  [ "$(probe resized.png ink $((cx - 60)) 110 $((cx + 140)) 290)" -ge 20 ] || fail "no key list drawn after F1"
else
  echo "xdotool not installed: real X events not checked"
fi

ls | grep -q '\.tmp' && fail "temporary files left behind: $(ls)"
[ $failures -eq 0 ] && echo "test_viewer_panel: all passed"
exit $((failures > 0))
