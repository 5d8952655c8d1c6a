#!/bin/sh
# The viewer's navigation and safety nets in a real window under Xvfb, driven by --script and by
# real X events (xdotool): a wheel step back from the default view, orbits and pans stay in the
# room, F / frame views the whole scene from outside it; a reference of another scene or size is refused, the
# error plot pauses away from the reference's camera and resumes back there; a failed load keeps
# the accumulation; quitting stops the frame in flight; an unlit scene is reported and a uniform
# sky lights it, and the environment is kept across loads; the wheel and W keep their steps a share
# of the distance in a 2 mm and a 2 km scene; the viewer and glint info start with the same method.
# Usage: test_viewer_nav.sh GLINT TMPDIR [KEEP_MODULES_LIB]
set -u
glint=$1
dir=$2/viewer_nav
keep_modules=${3:-}
command -v xdotool >/dev/null || { echo "xdotool not installed: skipped"; exit 77; }
screen=1280x800x24
. "$(dirname "$0")/viewer_harness.sh"

# ---- navigation through the script: the default view, one wheel step back (zoom by 1/0.85),
# far out, an orbit and a pan as far as they go, then a bookmark outside the room (black: its
# walls are lit only inside) and frame.
printf '1 0 1.5 40 0 0 40 0.8\n' >atelier.glint-bookmarks
cat >nav.txt <<'EOF'
wait 2
stats
zoom 1.17647
wait 2
stats
zoom 50
wait 1
stats
restore-bookmark 1
wait 1
stats
frame
wait 2
stats
screenshot framed.png
key r
orbit 60 0
pan 30 0
wait 1
stats
quit
EOF
view --size 160x90 --script nav.txt
rc=$?
[ $rc -eq 0 ] || fail "navigation session exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(wc -l <stats.txt)" -eq 6 ] || fail "navigation: expected 6 stats lines, got: $(cat out.txt)"
lit=$(awk -v m="$(field 1 mean)" 'BEGIN { print m / 10 }')
below 0 "$(field 1 mean)" || fail "the default view of the default scene is black"
below "$lit" "$(field 2 mean)" || fail "a wheel step back from the default view darkened it: $(field 1 mean) -> $(field 2 mean)"
below "$lit" "$(field 3 mean)" || fail "zooming far out left the room: mean $(field 3 mean)"
below "$(field 4 mean)" 1e-6 || fail "the bookmark outside the room is not black (mean $(field 4 mean))"
below "$lit" "$(field 5 mean)" || fail "frame did not bring the scene back: mean $(field 5 mean)"
[ -s framed.png ] || fail "no screenshot of the framed view"
below "$lit" "$(field 6 mean)" || fail "an orbit and a pan left the room: mean $(field 6 mean)"

# Every built-in scene's default view sees something lit, and keeps it one wheel step back.
for scene in atelier doorway showcase; do
  printf 'wait 1\nstats\nzoom 1.17647\nwait 1\nstats\nquit\n' >builtin.txt
  view "builtin:$scene" --size 96x54 --script builtin.txt
  grep '^stats ' out.txt >stats.txt
  below 0 "$(field 1 mean)" || fail "builtin:$scene: the default view is black"
  below 0 "$(field 2 mean)" || fail "builtin:$scene: a wheel step back is black"
done

# ---- the same through real X events: the wheel (button 5, a step back) and F after leaving the
# scene; the script sleeps while they arrive (long enough for a loaded machine: finding the window
# and delivering an event took over 4 s with the sanitizers and two busy cores).
cat >xnav.txt <<'EOF'
set panel 0
wait 2
stats
sleep 8
wait 2
stats
restore-bookmark 1
wait 1
stats
sleep 8
wait 2
stats
quit
EOF
rm -f out.txt # the last session's stats lines must not count for this one
view --size 320x180 --script xnav.txt &
viewer=$!
window=
if stats_lines 1; then
  window=$(xdotool search --sync --onlyvisible --name glint 2>/dev/null | head -n 1)
  # away from the panel, in the window's lower right
  # the cursor first, then the wheel: the viewer zooms only when the cursor was over the image in
  # the frame before (as a user's wheel follows the pointer's motion)
  xdotool mousemove --window "$window" 300 170
  sleep 0.5
  xdotool click 5
fi
stats_lines 3 && { xdotool windowfocus --sync "$window" 2>/dev/null; xdotool key f; }
wait $viewer
rc=$?
[ -n "$window" ] || fail "the viewer's window was not found: $(cat err.txt)"
[ $rc -eq 0 ] || fail "X-event navigation exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(wc -l <stats.txt)" -eq 4 ] || fail "X-event navigation: expected 4 stats lines, got: $(cat out.txt)"
[ "$(field 2 cam)" != "$(field 1 cam)" ] || fail "the wheel did not move the camera: $(field 1 cam) $(field 1 window) $(field 1 image)"
lit=$(awk -v m="$(field 1 mean)" 'BEGIN { print m / 10 }')
below "$lit" "$(field 2 mean)" || fail "a real wheel step back darkened the view: $(field 1 mean) -> $(field 2 mean)"
below "$(field 3 mean)" 1e-6 || fail "the bookmark outside the room is not black"
below "$lit" "$(field 4 mean)" || fail "the F key did not bring the scene back: mean $(field 4 mean)"

# ---- references: one with a description of this scene and size is taken; the error plot pauses
# (a note, no measurements) away from its camera and resumes at it (script and the C key); one
# of another scene or size is refused with the reason.
"$glint" render --size 96x54 --spp 4 --out ref.exr --quiet 2>err.txt || fail "render ref.exr: $(cat err.txt)"
"$glint" render builtin:doorway --size 96x54 --spp 1 --out other.exr --quiet 2>err.txt || fail "render other.exr: $(cat err.txt)"
"$glint" render --size 48x27 --spp 1 --out small.exr --quiet 2>err.txt || fail "render small.exr: $(cat err.txt)"
cat >reference.txt <<'EOF'
wait 2
stats
orbit 20 0
wait 1
stats
wait 2
stats
reference-camera
wait 2
stats
orbit -15 5
wait 1
key c
wait 2
stats
reference other.exr
reference small.exr
quit
EOF
view --size 96x54 --reference ref.exr --script reference.txt
rc=$?
[ $rc -eq 0 ] || fail "reference session exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(wc -l <stats.txt)" -eq 5 ] || fail "reference session: expected 5 stats lines, got: $(cat out.txt)"
[ "$(field 1 paused_note)" = "0" ] && [ "$(field 1 errors_measured)" -ge 1 ] ||
  fail "no error measured at the reference's camera: $(sed -n 1p stats.txt)"
[ "$(field 2 paused_note)" = "1" ] && [ "$(field 3 error_paused)" = "1" ] || fail "no pause note away from the reference's camera"
[ "$(field 3 errors_measured)" = "$(field 2 errors_measured)" ] || fail "the error was measured away from the reference's camera"
[ "$(field 4 paused_note)" = "0" ] && [ "$(field 4 error_paused)" = "0" ] || fail "reference-camera did not resume the plot"
[ "$(field 4 errors_measured)" -gt "$(field 3 errors_measured)" ] || fail "no error measured back at the reference's camera"
[ "$(field 4 cam)" = "$(field 1 cam)" ] || fail "reference-camera did not return to it: $(field 1 cam) vs $(field 4 cam)"
[ "$(field 5 paused_note)" = "0" ] && [ "$(field 5 cam)" = "$(field 1 cam)" ] || fail "the C key did not return to the reference's camera"
grep -q 'other.exr: rendered from another scene' err.txt || fail "a reference of another scene not refused: $(cat err.txt)"
grep -q 'small.exr: rendered at 48x27, not 96x54' err.txt || fail "a reference of another size not refused: $(cat err.txt)"

# ---- failed loads (a truncated GLB, an invalid glTF, a broken map) keep the accumulation
printf 'glTF\002\000\000\000\377\377\000\000' >truncated.glb
printf '{"asset": {"version": "2.0"}, "scenes": [{"nodes": [7]}]}' >invalid.gltf
printf 'not an image' >broken.exr
cat >loads.txt <<'EOF'
wait 3
stats
load truncated.glb
load invalid.gltf
env broken.exr
stats
wait 1
stats
quit
EOF
view --size 96x54 --script loads.txt
rc=$?
[ $rc -eq 0 ] || fail "failed-load session exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(field 2 resets)" = "$(field 1 resets)" ] || fail "a failed load reset the accumulation"
[ "$(field 2 frames)" -ge "$(field 1 frames)" ] && [ "$(field 3 frames)" -gt "$(field 1 frames)" ] ||
  fail "a failed load threw away frames: $(field 1 frames) -> $(field 2 frames), $(field 3 frames)"
for f in truncated.glb invalid.gltf broken.exr; do grep -q "$f" err.txt || fail "$f: no error reported"; done

# ---- quitting and loading stop the frame in flight: vsl+hl at 960x540, whose frames take seconds
# here (each in many parts); by the script, by a load, then by the Escape key. What is checked is
# what happened, counted by the viewer, not how long it took (a loaded or slower machine takes
# longer for everything): no frame was finished after the request, and at most the part in flight
# ran to its end (late_parts: the abort flag stops a part at its next chunk of pixels).
printf 'sleep 2\nstats\nquit\n' >quit.txt
view --size 960x540 --method vsl+hl --script quit.txt
rc=$?
[ $rc -eq 0 ] || fail "quit session exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
exit_field() { sed -n 's/^exit .*'"$1"'=\([0-9]*\).*/\1/p' out.txt; }
[ -n "$(exit_field late_parts)" ] || fail "no exit line: $(cat out.txt)"
[ "$(exit_field late_parts)" -le 1 ] || fail "quitting waited for $(exit_field late_parts) parts"
[ "$(exit_field frames_total)" = "$(field 1 frames_total)" ] ||
  fail "a frame was finished after the quit: $(field 1 frames_total) -> $(exit_field frames_total)"
# A load is a change too: once read, it stops the frame in flight.
printf 'sleep 2\nstats\nload builtin:showcase\nstats\nquit\n' >loadstop.txt
view --size 960x540 --method vsl+hl --script loadstop.txt
grep '^stats ' out.txt >stats.txt
[ "$(field 2 scene)" = "builtin:showcase" ] || fail "the load during a slow frame did not happen: $(cat err.txt)"
[ "$(field 2 late_parts)" -le 1 ] || fail "the load waited for $(field 2 late_parts) parts"
printf 'sleep 2\nstats\nsleep 120\nquit\n' >escape.txt
rm -f out.txt # the last session's stats lines must not count for this one
view --size 960x540 --method vsl+hl --script escape.txt &
viewer=$!
if stats_lines 1; then
  window=$(xdotool search --sync --onlyvisible --name glint 2>/dev/null | head -n 1)
  xdotool windowfocus --sync "$window" 2>/dev/null
  xdotool key Escape
fi
wait $viewer
rc=$?
[ $rc -eq 0 ] || fail "Escape session exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ -n "$(exit_field late_parts)" ] && [ "$(exit_field late_parts)" -le 1 ] ||
  fail "Escape waited for $(exit_field late_parts) parts: $(cat out.txt)"

# ---- a scene without light: warned in the terminal and noted for the panel; the uniform sky
# lights it, the K key takes it away again; the environment stays across loads until cleared.
cat >unlit.gltf <<'EOF'
{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
 "buffers": [{"byteLength": 60, "uri": "data:application/octet-stream;base64,AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAACAPwAAgD8AAAAAAACAvwAAgD8AAAAAAAABAAIAAAACAAMA"}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
               {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]}
EOF
cat >sky.txt <<'EOF'
wait 1
stats
sky
wait 2
stats
key k
sleep 1
wait 2
stats
sky
load builtin:doorway
wait 1
stats
env none
wait 1
stats
quit
EOF
view unlit.gltf --size 96x54 --script sky.txt
rc=$?
[ $rc -eq 0 ] || fail "unlit session exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(wc -l <stats.txt)" -eq 5 ] || fail "unlit session: expected 5 stats lines, got: $(cat out.txt)"
grep -q 'no light' err.txt || fail "no warning about the missing light: $(cat err.txt)"
grep -q 'uniform sky' err.txt || fail "the warning does not offer the uniform sky: $(cat err.txt)"
[ "$(field 1 unlit_note)" = "1" ] && below "$(field 1 mean)" 1e-6 || fail "the unlit scene: no note, or not black: $(sed -n 1p stats.txt)"
[ "$(field 2 env)" = "sky" ] && [ "$(field 2 unlit_note)" = "0" ] && below 0.01 "$(field 2 mean)" ||
  fail "the uniform sky did not light the scene: $(sed -n 2p stats.txt)"
[ "$(field 3 env)" = "-" ] && [ "$(field 3 unlit_note)" = "1" ] || fail "the K key did not take the sky away: $(sed -n 3p stats.txt)"
[ "$(field 4 scene)" = "builtin:doorway" ] && [ "$(field 4 env)" = "sky" ] || fail "the sky did not stay across a load: $(sed -n 4p stats.txt)"
[ "$(field 5 env)" = "-" ] || fail "env none did not clear the environment"

# ---- zoom and fly at any scale, through real X events: the wheel (three steps in) and W held for
# a second move the camera by a share of its distance to what it looks at, never to it or through
# it, whether the scene spans 2 mm or 2 km (the quad above, scaled; lit by the uniform sky).
cat >scaled.txt <<'EOF'
set panel 0
sky
wait 1
stats
screenshot ready.png
wait-file wheeled
sleep 0.5
wait 1
stats
wait-file flown
sleep 0.5
wait 1
stats
quit
EOF
for s in 0.001 1000; do
  sed "s/\"nodes\": \[{\"mesh\": 0}\]/\"nodes\": [{\"mesh\": 0, \"scale\": [$s, $s, $s]}]/" unlit.gltf >scaled.gltf
  rm -f wheeled flown
  view_bg ready.png scaled.gltf --size 160x90 --script scaled.txt
  if [ -n "$win" ]; then
    xdotool mousemove --window "$win" 80 45 click 4 sleep 0.3 click 4 sleep 0.3 click 4
    touch wheeled
    stats_lines 2
    xdotool windowfocus --sync "$win" 2>/dev/null
    xdotool keydown w sleep 1 keyup w
  fi
  view_end "scale $s" wheeled flown
  # distances from the camera to the quad's centre (the origin), over the scale
  d=$(for i in 1 2 3; do field $i cam; done | awk -F, -v s="$s" '{ printf "%g ", sqrt($1 * $1 + $2 * $2 + $3 * $3) / s }')
  set -- $d
  awk -v a="${1:-0}" -v b="${2:-0}" 'BEGIN { exit !(a > 0 && b > 0.4 * a && b < 0.9 * a) }' ||
    fail "scale $s: three wheel steps in took the camera from $1 to $2 (scene units)"
  awk -v b="${2:-0}" -v c="${3:-0}" 'BEGIN { exit !(b > 0 && c > 0.1 * b && c < 0.95 * b) }' ||
    fail "scale $s: a second of W took the camera from $2 to $3 (scene units)"
  for i in 1 2 3; do below 0.01 "$(field $i mean)" || fail "scale $s: view $i is black: $(sed -n ${i}p stats.txt)"; done
done

# ---- one default method: the viewer's and glint info's
[ "$(field 1 method)" = "vsl" ] || fail "the viewer does not start with vsl: $(field 1 method)"
"$glint" info >info.txt 2>&1 || fail "glint info failed: $(cat info.txt)"
grep -q '^method: *vsl$' info.txt || fail "glint info's default method is not vsl: $(grep method info.txt)"

if [ $failures -ne 0 ]; then echo "test_viewer_nav: $failures failures"; exit 1; fi
echo "test_viewer_nav: all checks passed"
