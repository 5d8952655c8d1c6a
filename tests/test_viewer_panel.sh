#!/bin/sh
# The viewer's panel and overlay under Xvfb, read from its own screenshots: the panel docks beside
# the image (the window's image region matches the render pixel for pixel at the centre, at 960x540
# and 480x270) and stays on-screen after resizes; the overlay writes in the image's corner; F1
# and ? show the key list; pause stops the frame count and --spp stops it at N; the image while
# moving is at the full resolution and not in blocks; dragging the panel's edge keeps the accumulation
# until the release; collapsed, the panel leaves the image whole beside it; at twice the content
# scale (HiDPI) the panel and text are twice the size and clicks and drags land where they are
# drawn. Through --script, and the keys, clicks, drags and resizes also through real X events
# (xdotool).
# Usage: test_viewer_panel.sh GLINT TMPDIR KEEP_MODULES_LIB PNG_PROBE
set -u
glint=$1
dir=$2/viewer_panel
keep_modules=$3
probe=$4
# A screen wide enough for a 960x540 image beside the panel; resources (Xft.dpi for HiDPI) kept
# between the viewer sessions.
screen=1920x1080x24
xvfb_args=-noreset
. "$(dirname "$0")/viewer_harness.sh"
probe() { "$probe" "$@" || echo 999999; }

# ---- the panel beside the image, the overlay, the help ----------------------------------------
cat >docked.txt <<'EOF'
wait 1
pause
wait-held
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
wait-held
stats
sleep 1
stats
resume
wait 2
stats
set spp 2
wait-held
stats
set spp 0
key space
wait-held
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
# (not `wait 3`: a loaded machine may render fewer than 3 frames in the second, and wait for ever)
printf 'wait 1\nsleep 2\nwait-held\nstats\nquit\n' >timelimit.txt
view --size 160x90 --time 1 --script timelimit.txt
grep '^stats ' out.txt >stats.txt
[ "$(field 1 time_limit)" = 1 ] && [ "$(field 1 held)" = 1 ] || fail "--time 1 did not stop: $(cat stats.txt)"
view --size 160x90 --spp 0 --script limit.txt && fail "--spp 0 accepted"
view view --help
grep -q 'F1 or ?' out.txt && grep -q -- '--spp N' out.txt || fail "--help lacks the key list or --spp"

# ---- the wheel zooms over the image only: turned in the frame the cursor arrives on the panel
# (the panel's hover still the last frame's, over the image), it does nothing to the view.
cat >wheel.txt <<'EOF'
wait 1
stats
wheel 80 45 1
wait 1
stats
sleep 0.3
wheel 300 45 1
sleep 0.3
stats
quit
EOF
view --size 160x90 --script wheel.txt
rc=$?
[ $rc -eq 0 ] || fail "wheel script exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(field 1 window)" = 400x90 ] || fail "the wheel session's window is $(field 1 window), not 400x90"
[ "$(field 2 cam)" != "$(field 1 cam)" ] || fail "the wheel over the image did not zoom"
[ "$(field 3 cam)" = "$(field 2 cam)" ] || fail "the wheel over the panel zoomed: $(field 2 cam) -> $(field 3 cam)"

# ---- the image while moving: at the full resolution, not in blocks --------------------------------
rm -f moving.png
cat >moving.txt <<'EOF'
wait 1
spin 90 1.5
stats
window-shot moving.png
quit
EOF
view --size 480x270 --script moving.txt
rc=$?
[ $rc -eq 0 ] || fail "moving script exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(field 1 width)x$(field 1 height)" = 480x270 ] ||
  fail "the image while moving is $(field 1 width)x$(field 1 height), not the render's 480x270"
b=$(probe moving.png blocky 0 60 480 270)
[ "$b" -le 5 ] || fail "the image while moving is blocky: $b per mille of 3x3 windows flat"

# ---- real X events: resizes keep the panel on-screen, its edge drags, F1, ? and Space ----------
# Each script waits for a file the test makes once its events are sent (a loaded machine delivers
# them late: any fixed wait can be too short).
if command -v xdotool >/dev/null; then
  cat >xevents.txt <<'EOF'
wait 1
set exposure -30
stats
screenshot ready.png
wait-file sent
sleep 1
stats
window-shot resized.png
quit
EOF
  rm -f sent
  view_bg ready.png --size 480x270 --script xevents.txt
  if [ -n "$win" ]; then
    xdotool windowsize "$win" 200 120
    sleep 0.5
    xdotool windowsize "$win" 700 300
    sleep 0.5
    # Drag the panel's left edge 40 to the left: it widens from its default 360.
    xdotool mousemove --window "$win" 341 150 sleep 0.2 mousedown 1 sleep 0.1
    for x in 331 321 311 301; do xdotool mousemove --window "$win" $x 150 sleep 0.1; done
    xdotool sleep 0.3 mouseup 1
    sleep 0.5
    xdotool windowfocus "$win" 2>/dev/null
    # F1 shows the list, ? hides it, F1 shows it again (a key lost leaves it hidden)
    xdotool key F1 sleep 0.5 key question sleep 0.5 key F1 sleep 0.5 key space
  fi
  view_end "the X events session" sent
  [ "$(field 2 window)" = 700x300 ] || fail "the window was not resized: $(field 2 window)"
  dock=$(field 2 dock)
  [ "$dock" -gt 0 ] && [ "$dock" -le 420 ] || fail "after resizes the panel is $dock wide in 700"
  [ "$dock" -ge 390 ] || fail "dragging its edge did not widen the panel: $dock"
  [ "$(field 2 image)" = "$((700 - dock))x300" ] || fail "image $(field 2 image) beside a $dock panel"
  [ "$(probe resized.png ink $((700 - dock)) 0 700 300)" -ge 10 ] || fail "no panel on-screen after resizes"
  [ "$(field 2 help)" = 1 ] || fail "F1, ?, F1 did not leave the key list shown"
  [ "$(field 2 paused)" = 1 ] || fail "the Space key did not pause"
  cx=$(((700 - dock) / 2))
  # The list's text over the image (shown black: exposure -30, so a noisy render has no ink; the
  # panel, right of it, has ink of its own).
  [ "$(probe resized.png ink $((cx - 60)) 110 $((cx + 140)) 290)" -ge 20 ] || fail "no key list drawn after F1"

  # ---- while the panel's edge is dragged the image keeps its size and accumulation (shown scaled
  # into the new place, its shape kept); the release starts one at the new size. Unfiltered, so
  # that the noisy image has bright specks to find. Collapsed, the
  # panel keeps a narrow column: the image beside it, its top-right corner free.
  cat >dragging.txt <<'EOF'
set exposure 2
wait 1
stats
screenshot ready.png
wait-file held
sleep 1
stats
window-shot held.png
screenshot stats-2.png
wait-file dropped
sleep 0.5
wait 1
stats
screenshot stats-3.png
wait-file collapsed
sleep 1
wait 2
stats
window-shot collapsed.png
screenshot collapsed-image.png
quit
EOF
  rm -f held dropped collapsed stats-2.png stats-3.png
  view_bg ready.png --size 480x270 --spp 2 --denoise off --script dragging.txt
  if [ -n "$win" ]; then
    xdotool mousemove --window "$win" 481 150 sleep 0.2 mousedown 1 sleep 0.1
    for x in 460 440 420 400 380; do xdotool mousemove --window "$win" $x 150 sleep 0.1; done
    touch held
    file_made stats-2.png
    xdotool mouseup 1
    touch dropped
    file_made stats-3.png
    # the collapse arrow, at the start of the panel's title bar
    dock=$(grep '^stats ' out.txt | sed -n 3p | tr ' ' '\n' | sed -n 's/^dock=//p')
    xdotool mousemove --window "$win" $((840 - ${dock:-0} + 10)) 9 click 1
  fi
  view_end "the panel drag session" held dropped collapsed
  [ "$(wc -l <stats.txt)" -eq 4 ] || fail "panel drag session: expected 4 stats lines, got: $(cat out.txt)"
  [ "$(field 2 image)" = 379x270 ] || fail "the held drag did not widen the panel: image $(field 2 image)"
  [ "$(field 2 resets)" = "$(field 1 resets)" ] && [ "$(field 2 width)x$(field 2 height)" = 480x270 ] ||
    fail "the accumulation restarted during the drag: $(sed -n 2p stats.txt)"
  [ "$(field 2 frames)" -ge "$(field 1 frames)" ] || fail "frames lost during the drag: $(field 1 frames) -> $(field 2 frames)"
  # Shown scaled with its shape kept: 379x213 in the middle of 379x270, black above and below,
  # the noisy image (bright at exposure 2) between; right of the overlay.
  [ "$(probe held.png ink 250 0 379 26)" -eq 0 ] && [ "$(probe held.png ink 250 244 379 270)" -eq 0 ] &&
    [ "$(probe held.png ink 250 40 379 230)" -gt 0 ] ||
    fail "the image held during the drag is not shown at its own shape, centred"
  [ "$(field 3 resets)" -gt "$(field 2 resets)" ] && [ "$(field 3 width)x$(field 3 height)" = 379x270 ] ||
    fail "the release did not start the new size: $(sed -n 3p stats.txt)"
  dock=$(field 4 dock)
  [ "$dock" -gt 0 ] && [ "$dock" -le 40 ] || fail "collapsed, the panel takes $dock"
  w=$((840 - dock))
  [ "$(field 4 image)" = "${w}x270" ] && [ "$(field 4 width)" = "$w" ] ||
    fail "collapsed, the image is not beside the panel: $(sed -n 4p stats.txt)"
  # The image's top-right corner is the render itself (no title bar over it); the column holds the arrow.
  d=$(probe collapsed.png diff collapsed-image.png $((w - 200)) 0 "$w" 30)
  awk -v d="$d" 'BEGIN { exit !(d < 3) }' || fail "something covers the image's top-right corner (differs by $d)"
  [ "$(probe collapsed.png ink "$w" 0 840 30)" -ge 10 ] || fail "no arrow in the collapsed panel's column"

  # ---- the bookmark buttons, clicked: "save 3" keeps the view, "3" brings it back after an orbit
  # (pt: its panel is short enough for the Camera section to show in a tall window).
  cat >bookmarks.txt <<'EOF'
wait 1
sleep 0.5
buttons
stats
screenshot ready.png
wait-file saved
sleep 0.5
orbit 30 0
sleep 0.5
buttons
stats
screenshot moved.png
wait-file restored
sleep 0.5
stats
quit
EOF
  rm -f moved.png saved restored
  view_bg ready.png --size 240x1000 --method pt --script bookmarks.txt
  click() { # click LABEL: the centre of the panel's button LABEL, where it was last listed
    set -- $(grep "^button .* $1\$" out.txt | tail -n 1)
    [ $# -ge 5 ] && xdotool mousemove --window "$win" $((($2 + $4) / 2)) $((($3 + $5) / 2)) click 1
  }
  if [ -n "$win" ]; then
    click '3##save' || fail "no save button for bookmark 3: $(grep '^button' out.txt)"
    touch saved
    file_made moved.png
    click '3##go' || fail "no restore button for bookmark 3"
  fi
  view_end "the bookmark buttons session" saved restored
  [ "$(field 2 bookmarks)" = 3 ] || fail "the save button did not set bookmark 3: $(field 2 bookmarks)"
  [ "$(field 2 cam)" != "$(field 1 cam)" ] || fail "the orbit did not move the camera"
  [ "$(field 3 cam)" = "$(field 1 cam)" ] || fail "the bookmark button did not restore the view: $(field 1 cam) vs $(field 3 cam)"
else
  echo "xdotool not installed: real X events not checked"
fi

# ---- a mouse drag orbits the camera; its moves come 30 a second and more, but once the drag is
# under way the window is drawn for the images they bring, not for every move (llvmpipe draws on the
# renderer's cores). Counted from the drag's 10th move (the press is drawn: the panel may claim it).
if command -v xdotool >/dev/null; then
  cat >orbitdrag.txt <<'EOF'
wait 1
stats
screenshot ready.png
wait-file begun
stats
wait-file dragged
stats
quit
EOF
  rm -f begun dragged
  view_bg ready.png --size 480x270 --script orbitdrag.txt
  if [ -n "$win" ]; then
    xdotool mousemove --window "$win" 240 135 sleep 0.3 mousedown 1 sleep 0.1
    for i in $(seq 1 50); do
      xdotool mousemove --window "$win" $((240 + 2 * i)) 135 sleep 0.03
      [ "$i" = 10 ] && touch begun && stats_lines 2
    done
    xdotool mouseup 1
  fi
  view_end "the orbit drag session" begun dragged
  [ "$(field 3 cam)" != "$(field 2 cam)" ] || fail "the drag did not orbit: $(field 2 cam) -> $(field 3 cam)"
  d=$(($(field 3 frames_drawn) - $(field 2 frames_drawn))) n=$(($(field 3 images) - $(field 2 images)))
  [ "$d" -le $((n + 10)) ] || fail "40 moves of a drag drew $d frames for $n images (want at most images + 10)"
fi

# ---- HiDPI: the window's content scale (X11 takes it from the Xft.dpi resource) sizes the font,
# the panel and the light markers; a click lands on the scaled pause button, a ctrl+drag moves the
# light with the cursor. At 96 dpi (scale 1) and 192 (scale 2), the same session.
if command -v xdotool >/dev/null && command -v xrdb >/dev/null; then
  cat >hidpi.txt <<'EOF'
set exposure -30
wait 1
sleep 0.5
stats
buttons
window-shot hidpi.png
wait-file sent
sleep 1
stats
quit
EOF
  for dpi in 96 192; do
    echo "Xft.dpi: $dpi" | xrdb -nocpp -merge
    rm -f sent
    view_bg hidpi.png --size 480x540 --spp 1 --script hidpi.txt
    if [ -n "$win" ]; then
      # the pause button's centre, as the panel drew it
      set -- $(grep '^button .* pause (Space)$' out.txt)
      [ $# -ge 5 ] && xdotool mousemove --window "$win" $((($2 + $4) / 2)) $((($3 + $5) / 2)) click 1
      # ctrl+drag from the light's marker, 40 right and 20 down
      xy=$(grep '^stats ' out.txt | head -n 1 | tr ' ' '\n' | sed -n 's/^light_xy=//p')
      lx=$(printf '%.0f' "${xy%,*}") ly=$(printf '%.0f' "${xy#*,}")
      xdotool mousemove --window "$win" "$lx" "$ly" keydown ctrl sleep 0.3 mousedown 1 sleep 0.3
      for d in 10 20 30 40; do xdotool mousemove --window "$win" $((lx + d)) $((ly + d / 2)) sleep 0.2; done
      xdotool sleep 0.5 mouseup 1 sleep 0.2 keyup ctrl
    fi
    view_end "the $dpi dpi session" sent
    scale=$(field 1 content_scale)
    [ "$scale" = $((dpi / 96)) ] || fail "$dpi dpi: content scale $scale"
    [ "$(field 2 paused)" = 1 ] || fail "$dpi dpi: a click on the pause button did not pause"
    moved=$(awk -v a="$(field 1 light_xy)" -v b="$(field 2 light_xy)" 'BEGIN {
      split(a, p, ","); split(b, q, ","); dx = q[1] - p[1] - 40; dy = q[2] - p[2] - 20
      print (dx * dx + dy * dy <= 9) }')
    [ "$moved" = 1 ] || fail "$dpi dpi: the light's marker did not follow the cursor: $(field 1 light_xy) -> $(field 2 light_xy)"
    eval "dock_$scale=$(field 1 dock) ink_$scale=$(probe hidpi.png inkrows 0 0 480 270)"
    cp hidpi.png "hidpi-$dpi.png"
  done
  xrdb -remove
  # Twice the scale: the panel twice as wide, the overlay's text about twice as tall.
  [ "${dock_2:-0}" -ge $((2 * ${dock_1:-0} - 2)) ] && [ "${dock_2:-0}" -le $((2 * ${dock_1:-0} + 2)) ] ||
    fail "the panel did not follow the content scale: ${dock_1:-?} at scale 1, ${dock_2:-?} at 2"
  awk -v a="${ink_1:-0}" -v b="${ink_2:-0}" 'BEGIN { exit !(a > 0 && b >= 1.6 * a) }' ||
    fail "the text did not follow the content scale: ${ink_1:-?} rows of ink at scale 1, ${ink_2:-?} at 2"
else
  echo "xdotool or xrdb not installed: HiDPI not checked"
fi

ls | grep -q '\.tmp' && fail "temporary files left behind: $(ls)"
[ $failures -eq 0 ] && echo "test_viewer_panel: all passed"
exit $((failures > 0))
