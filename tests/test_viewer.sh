#!/bin/sh
# The viewer in a real window under Xvfb, driven by --script: it opens on the default scene (a
# built-in; the load action opens another by its builtin:NAME),
# display-only changes keep the accumulated frames, estimator and camera changes reset them (the
# many-light and vsl+hl highlight parameters included), screenshots and EXR exports appear
# (numbered, never overwriting; vsl+hl's with a highlights layer), a bad file leaves the viewer
# running, a bad script line or value is reported with its line number.
# Lights move and dim live, camera bookmarks round-trip through their file (a malformed one is
# reported and ignored), tone mappers switch without a reset, a reference image gives the error
# and its false-colour view (one of another size is refused). Captures are the image shown, at the
# render's size, with the camera it was rendered from; the stats count the images shown.
# Usage: test_viewer.sh GLINT TMPDIR [KEEP_MODULES_LIB]
set -u
glint=$1
dir=$2/viewer
keep_modules=${3:-}
screen=1024x768x24
. "$(dirname "$0")/viewer_harness.sh"

printf 'not a scene' >broken.gltf
cat >session.txt <<'EOF'
wait 2
stats
set exposure 1.5
set show direct
wait 1
stats
set show estimator
set max-depth 3
wait 1
stats
set show all
orbit 25 -10
pan 0.1 0.05
zoom 0.8
wait 2
stats
key r
wait 1
screenshot shot.png
screenshot shot.png
export image.exr
load broken.gltf
wait 1
stats
load builtin:showcase
wait 1
stats
quit
EOF
view --size 320x180 --script session.txt
rc=$?
[ $rc -eq 0 ] || fail "scripted session exited $rc: $(cat err.txt)"
# stats lines: 1 start, 2 after display changes, 3 after max-depth, 4 after camera motion, 5 after a
# bad load, 6 after loading another built-in scene
grep '^stats ' out.txt >stats.txt
[ "$(wc -l <stats.txt)" -eq 6 ] || fail "expected 6 stats lines, got: $(cat out.txt)"
default_scene=$(field 1 scene)
case $default_scene in builtin:?*) ;; *) fail "the viewer did not open a built-in scene: $default_scene" ;; esac
[ "$(field 1 frames)" -ge 2 ] || fail "no frames rendered"
[ "$(field 2 resets)" = "$(field 1 resets)" ] || fail "a display change reset the accumulation"
[ "$(field 2 frames)" -gt "$(field 1 frames)" ] || fail "frames did not keep accumulating across a display change"
[ "$(field 2 exposure)" = "1.5" ] && [ "$(field 2 show)" = "direct" ] || fail "display settings not applied"
[ "$(field 3 resets)" -gt "$(field 2 resets)" ] || fail "max-depth did not reset the accumulation"
[ "$(field 3 show)" = "estimator" ] || fail "show estimator not applied"
[ "$(field 3 max_depth)" = "3" ] || fail "max-depth not applied"
[ "$(field 4 resets)" -gt "$(field 3 resets)" ] || fail "camera motion did not reset the accumulation"
[ "$(field 5 scene)" = "$default_scene" ] || fail "a bad scene file replaced the scene"
[ "$(field 6 scene)" = "builtin:showcase" ] || fail "load builtin:showcase did not open it: $(field 6 scene)"
grep -q 'broken.gltf' err.txt || fail "the bad scene file's error was not reported"
[ -s shot.png ] && [ -s shot-1.png ] || fail "screenshots missing or overwritten: $(ls)"
[ -s image.exr ] || fail "EXR export missing"
# The export holds the image and its component layers.
head -c 2000 image.exr | grep -q 'direct.R' || fail "EXR export lacks the direct layer"
ls | grep -q '\.tmp' && fail "temporary files left behind: $(ls)"

# The effect plan and the seed are settings of the render too: each change restarts the
# accumulation (the panel's and the script's through the parameter table).
cat >plan.txt <<'EOF'
wait 1
stats
set plan full
wait 1
stats
set seed 7
wait 1
stats
quit
EOF
view --size 48x27 --script plan.txt
rc=$?
[ $rc -eq 0 ] || fail "plan and seed session exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(field 2 plan)" = "full" ] && [ "$(field 2 resets)" -gt "$(field 1 resets)" ] ||
  fail "set plan full did not restart the accumulation: $(sed -n 2p stats.txt)"
[ "$(field 3 seed)" = "7" ] && [ "$(field 3 resets)" -gt "$(field 2 resets)" ] ||
  fail "set seed 7 did not restart the accumulation: $(sed -n 3p stats.txt)"

# The many-light parameters change live: each change resets the accumulation and shows in the
# stats; a bad value is reported with its line and leaves the last good value. Then the same for
# vsl+hl's highlight parameters, whose component the display can show alone and the export holds.
cat >manylight.txt <<'EOF'
set method vsl
set vsl-count 128
wait 1
stats
set radius-mult 4
set candidates 8
set trace-glossy 0.4
wait 1
stats
set radius-mult -2
stats
set method vsl+hl
set secondary-rays 6
wait 1
stats
set show highlights
wait 1
stats
screenshot highlights.png
export highlights.exr
set secondary-rays 4
wait 1
stats
set clusters 2
wait 1
stats
set merge off
wait 1
stats
set merge trace
wait 1
stats
set merge on
wait 1
stats
set clusters 99
stats
quit
EOF
view --size 48x27 --script manylight.txt # tiny: the run time is per pixel
rc=$?
[ $rc -eq 1 ] || fail "many-light session with bad values: exit $rc, expected 1: $(cat err.txt)"
grep -q 'manylight.txt:10:' err.txt || fail "bad radius multiplier not reported with its line: $(cat err.txt)"
grep -q 'manylight.txt:36:' err.txt || fail "bad cluster count not reported with its line: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(wc -l <stats.txt)" -eq 11 ] || fail "many-light session: expected 11 stats lines, got: $(cat out.txt)"
[ "$(field 1 method)" = "vsl" ] && [ "$(field 1 vsl_count)" = "128" ] || fail "method or light count not applied"
[ "$(field 1 virtual_lights)" -gt 0 ] || fail "vsl traced no virtual lights"
[ "$(field 2 radius_mult)" = "4" ] && [ "$(field 2 candidates)" = "8" ] && [ "$(field 2 trace_glossy)" = "0.4" ] ||
  fail "radius, candidates or trace-glossy not applied"
[ "$(field 2 resets)" -gt "$(field 1 resets)" ] || fail "a many-light change did not reset the accumulation"
# the panel states the new settings' cost beside the last ones'
below 0 "$(field 2 cost_ms)" && below 0 "$(field 2 cost_before_ms)" ||
  fail "no cost of the settings before and after the change: $(sed -n 2p stats.txt)"
[ "$(field 3 radius_mult)" = "4" ] || fail "a bad radius multiplier replaced the last good one"
# stats lines 4 on: vsl+hl (with fewer secondary rays than the default 8, to save time), then shown
# as highlights only, then N, K and merge changed
[ "$(field 1 secondary_rays)" = "8" ] && [ "$(field 1 clusters)" = "4" ] && [ "$(field 1 merge)" = "auto" ] ||
  fail "highlight parameters do not start at their defaults: $(sed -n 1p stats.txt)"
[ "$(field 4 method)" = "vsl+hl" ] && [ "$(field 4 secondary_rays)" = "6" ] || fail "vsl+hl not applied: $(sed -n 4p stats.txt)"
[ "$(field 4 resets)" -gt "$(field 3 resets)" ] || fail "switching to vsl+hl did not reset the accumulation"
[ "$(field 4 hl_lobes)" -gt 0 ] || fail "vsl+hl lit no highlight lobes"
[ "$(field 4 plan_highlights)" = "1" ] || fail "the default scene's plan must run the highlight pass"
[ "$(field 5 show)" = "highlights" ] || fail "show highlights not applied"
[ "$(field 5 resets)" = "$(field 4 resets)" ] || fail "showing the highlights reset the accumulation"
[ "$(field 5 frames)" -gt "$(field 4 frames)" ] || fail "frames did not keep accumulating when showing the highlights"
for change in "6 secondary_rays 4" "7 clusters 2" "8 merge off" "9 merge trace" "10 merge on"; do
  set -- $change
  [ "$(field "$1" "$2")" = "$3" ] || fail "$2 $3 not applied: $(sed -n "$1p" stats.txt)"
  [ "$(field "$1" resets)" -gt "$(field $(($1 - 1)) resets)" ] || fail "$2 $3 did not reset the accumulation"
done
[ "$(field 11 clusters)" = "2" ] || fail "a bad cluster count replaced the last good one"
[ -s highlights.png ] || fail "vsl+hl screenshot missing"
[ -s highlights.exr ] || fail "vsl+hl EXR export missing"
head -c 2000 highlights.exr | grep -q 'highlights.R' || fail "the vsl+hl export lacks the highlights layer"

# Every many-light option is a `set` parameter (the table in params.c), those the panel never had
# included, and the stats show each one by its name.
cat >params.txt <<'EOF'
set method vpl
set rows 64
set clamp-growth off
set vpl-glossy on
set per-pixel all
wait 1
stats
quit
EOF
view --size 48x27 --script params.txt
rc=$?
[ $rc -eq 0 ] || fail "setting rows, clamp-growth, vpl-glossy, per-pixel: exit $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(field 1 rows)" = "64" ] && [ "$(field 1 clamp_growth)" = "off" ] && [ "$(field 1 vpl_glossy)" = "on" ] &&
  [ "$(field 1 per_pixel)" = "all" ] || fail "rows, clamp-growth, vpl-glossy or per-pixel not applied: $(cat stats.txt)"
[ "$(field 1 virtual_lights)" -gt 0 ] || fail "vpl with glossy VPLs traced no virtual lights"

# Lights: dimming and moving the default scene's first light reset the accumulation and change the
# image; a tone mapper change does not reset; a camera bookmark saved, the view moved, the
# bookmark restored gives the saved view back, from NAME.glint-bookmarks for builtin:NAME.
cat >edits.txt <<'EOF'
wait 2
stats
set light 0
set light-intensity 0.25
wait 2
stats
export ref.exr
move-light 0 0 -1 0
wait 2
stats
set tonemap clamp
wait 1
stats
save-bookmark 1
orbit 30 0
wait 1
stats
restore-bookmark 1
wait 1
stats
move-light 7 0 1 0
key ctrl+2
key shift+1
wait 1
stats
quit
EOF
view --size 96x54 --script edits.txt
rc=$?
[ $rc -eq 1 ] || fail "light session: exit $rc, expected 1 (a bad light index): $(cat err.txt)"
grep -q 'edits.txt:21: no light 7' err.txt || fail "a bad light index not reported with its line: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(wc -l <stats.txt)" -eq 7 ] || fail "light session: expected 7 stats lines, got: $(cat out.txt)"
[ "$(field 1 lights)" -ge 1 ] || fail "the default scene lists no light: $(sed -n 1p stats.txt)"
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.4f", a / b }'; }
[ "$(field 2 light)" = "0" ] && [ "$(field 2 light_intensity)" = "0.25" ] || fail "light intensity not applied: $(sed -n 2p stats.txt)"
[ "$(field 2 resets)" -gt "$(field 1 resets)" ] || fail "a light intensity change did not reset the accumulation"
below "$(ratio "$(field 2 mean)" "$(field 1 mean)")" 0.6 || fail "dimming the light did not darken the image: $(field 1 mean) -> $(field 2 mean)"
[ "$(field 3 resets)" -gt "$(field 2 resets)" ] || fail "moving a light did not reset the accumulation"
y2=$(field 2 light_pos | cut -d, -f2)
y3=$(field 3 light_pos | cut -d, -f2)
below "$(awk -v a="$y2" -v b="$y3" 'BEGIN { d = a - b - 1; print d < 0 ? -d : d }')" 0.001 || fail "the light did not move down by 1: $y2 -> $y3"
r=$(ratio "$(field 3 mean)" "$(field 2 mean)")
below 1.05 "$r" || below "$r" 0.95 || fail "moving the light did not change the image (mean ratio $r)"
[ "$(field 4 tonemap)" = "clamp" ] || fail "tone mapper not applied"
[ "$(field 4 resets)" = "$(field 3 resets)" ] || fail "a tone mapper change reset the accumulation"
[ "$(field 4 frames)" -gt "$(field 3 frames)" ] || fail "frames did not keep accumulating across a tone mapper change"
[ "$(field 5 cam)" != "$(field 4 cam)" ] || fail "orbit did not move the camera"
[ "$(field 6 cam)" = "$(field 4 cam)" ] || fail "restoring a bookmark did not restore the view: $(field 4 cam) vs $(field 6 cam)"
[ "$(field 6 bookmarks)" = "1" ] || fail "bookmark 1 not listed: $(field 6 bookmarks)"
[ "$(field 7 bookmarks)" = "12" ] || fail "ctrl+2 did not save bookmark 2: $(field 7 bookmarks)"
bookmarks=${default_scene#builtin:}.glint-bookmarks
grep -q '^1 ' "$bookmarks" && grep -q '^2 ' "$bookmarks" || fail "the bookmark file lacks bookmark 1 or 2: $(cat "$bookmarks")"
saved_cam=$(field 4 cam)

# The bookmark file, read back by a new session; then a malformed one: one message, ignored.
printf 'restore-bookmark 1\nwait 1\nstats\nquit\n' >restore.txt
view --size 96x54 --script restore.txt
rc=$?
[ $rc -eq 0 ] || fail "restoring a saved bookmark: exit $rc: $(cat err.txt)"
[ "$(grep '^stats ' out.txt | tr ' ' '\n' | sed -n 's/^cam=//p')" = "$saved_cam" ] || fail "the bookmark file did not restore the view"
printf '1 0 1 2 0.1 nonsense\n' >"$bookmarks"
view --size 96x54 --script restore.txt
rc=$?
[ $rc -eq 1 ] || fail "restoring from a malformed bookmark file: exit $rc, expected 1"
grep -q "$bookmarks:1: not a bookmark line" err.txt || fail "malformed bookmark file not reported: $(cat err.txt)"
[ "$(grep -c 'bookmark' err.txt)" -eq 2 ] || fail "expected one message for the file and one for the restore: $(cat err.txt)"
grep -q '^stats ' out.txt || fail "the viewer did not keep running after a malformed bookmark file"

# A reference image (of the dimmed light, so the error cannot be zero): the error is measured,
# shown in false colour (a display change: no reset); a reference of another size is refused
# with a message and the viewer keeps running.
cat >reference.txt <<'EOF'
wait 2
stats
set show error
wait 1
stats
screenshot error.png
reference highlights.exr
wait 1
stats
quit
EOF
view --size 96x54 --reference ref.exr --script reference.txt
rc=$?
[ $rc -eq 0 ] || fail "reference session: exit $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(wc -l <stats.txt)" -eq 3 ] || fail "reference session: expected 3 stats lines, got: $(cat out.txt)"
below 0.05 "$(field 1 rel_error)" && below "$(field 1 rel_error)" 100 || fail "no plausible error against the reference: $(field 1 rel_error)"
[ "$(field 2 show)" = "error" ] || fail "the error view not shown"
[ "$(field 2 resets)" = "$(field 1 resets)" ] || fail "the error view reset the accumulation"
[ -s error.png ] || fail "no screenshot of the error view"
grep -q 'highlights.exr: the reference is 48x27 but the render is 96x54' err.txt ||
  fail "a reference of another size not reported: $(cat err.txt)"
[ "$(field 3 frames)" -gt "$(field 2 frames)" ] || fail "the viewer stopped after a reference of another size"

# A bad script line is reported with its line number, before any window opens.
# ---- captures: the image shown, linear, at the render's size, with its own camera -----------
# At rest and paused, with the display's filter off from the start (and with it the display's own
# samples), a capture is the film's image (the display's history holds the same samples, in
# float); with it on it is not, and the export (the estimate) is the same pixels either way. An orbit and a capture in one UI frame: the image shown is still
# the one before the orbit, and the capture says so (its camera, not the new one; not the latest).
# Soon after, the new view's first images: at the render's full size, as every image is. The stats
# count the images the window took, and the frames it drew.
cat >capture.txt <<'EOF'
wait 1
pause
wait-held
set denoise off
stats
capture still.exr
export still-export.exr
set denoise on
capture still-denoised.exr
export still-export-denoised.exr
resume
orbit 20 0
capture moved.exr
stats
sleep 0.1
capture soon.exr
stats
wait 1
pause
wait-held
capture moved-rest.exr
stats
sleep 2
stats
resume
stats
EOF
# 20 steps of a scripted drag, then the count
for i in $(seq 20); do printf 'orbit 1 0\nsleep 0.05\n'; done >>capture.txt
printf 'stats\nquit\n' >>capture.txt
rm -f still*.exr moved*.exr soon*.exr
view --size 160x90 --denoise off --script capture.txt
rc=$?
[ $rc -eq 0 ] || fail "capture script exited $rc: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
for f in still.exr still-denoised.exr moved.exr soon.exr moved-rest.exr; do
  grep -q "^glint: wrote $f\$" out.txt || fail "capture $f not reported: $(cat out.txt err.txt)"
done
desc() { exrheader "$1" 2>/dev/null | tr -d '\n'; } # the header, its description on one line
rel() { sed -n 's/^rel_l2=\([^ ]*\) .*/\1/p' cmp.txt; }
if command -v exrheader >/dev/null; then
  case $(desc still.exr) in *'"width": 160,  "height": 90'*'"preview": false'*'"latest": true'*) ;;
  *) fail "still.exr: not a full-resolution capture of the latest state: $(desc still.exr)" ;; esac
  "$glint" compare still.exr still-export.exr >cmp.txt 2>&1 || fail "compare still: $(cat cmp.txt)"
  below "$(rel)" 1e-5 || fail "the paused capture, unfiltered, is not the exported image: $(cat cmp.txt)"
  "$glint" compare still-denoised.exr still-export.exr >cmp.txt 2>&1 || fail "compare denoised: $(cat cmp.txt)"
  below 1e-4 "$(rel)" || fail "the filtered capture is the film's image: $(cat cmp.txt)"
  "$glint" compare still-export-denoised.exr still-export.exr >cmp.txt 2>&1 || fail "compare exports: $(cat cmp.txt)"
  grep -q '^rel_l2=0 ' cmp.txt || fail "the filter changed the exported estimate: $(cat cmp.txt)"
  case $(desc moved.exr) in *'"latest": false'*) ;; *) fail "moved.exr claims the orbit's image" ;; esac
  # Its camera is the one before the orbit: compare takes it against the still capture, and
  # refuses it against the capture at rest after the orbit.
  "$glint" compare moved.exr still.exr >cmp.txt 2>&1 || fail "moved vs still: $(cat cmp.txt)"
  "$glint" compare moved.exr moved-rest.exr >cmp.txt 2>&1 && fail "moved.exr has the new camera"
  grep -q 'seen from' cmp.txt || fail "moved vs moved-rest: $(cat cmp.txt)"
  case $(desc soon.exr) in *'"width": 160,  "height": 90'*'"image_size": [160, 90]'*) ;;
  *) fail "soon.exr: not at the render's full size: $(desc soon.exr)" ;; esac
fi
i1=$(field 1 images) i4=$(field 4 images) f4=$(field 4 images_full)
[ "${i1:-0}" -ge 1 ] && [ "${i4:-0}" -gt "$i1" ] || fail "images counted $i1 then $i4"
[ "${f4:-0}" = "$i4" ] || fail "full-resolution images $f4 of $i4: every image is at full resolution"
[ "$(field 1 render_size)" = 160x90 ] || fail "render_size $(field 1 render_size)"
# Paused, nothing changes: the window is drawn twice a second (and once more as the panel settles),
# not at 60 frames a second (the renderer's cores draw it). An upper bound: a slow machine draws less.
d4=$(field 4 frames_drawn) d5=$(field 5 frames_drawn)
[ -n "$d4" ] && [ -n "$d5" ] && [ $((d5 - d4)) -ge 1 ] && [ $((d5 - d4)) -le 16 ] ||
  fail "frames drawn in 2 s at rest: ${d4:-?} -> ${d5:-?} (want 1 to 16)"
# Moving, the window is drawn for the images the moves bring, not for each step of the drag (a
# scripted orbit as a mouse drag): 20 steps draw at most the images published and a few more.
d6=$(field 6 frames_drawn) d7=$(field 7 frames_drawn) i6=$(field 6 images) i7=$(field 7 images)
[ -n "$d6" ] && [ -n "$d7" ] && [ -n "$i6" ] && [ -n "$i7" ] && [ $((d7 - d6)) -le $((i7 - i6 + 8)) ] ||
  fail "frames drawn during 20 orbit steps: ${d6:-?} -> ${d7:-?}, images ${i6:-?} -> ${i7:-?} (want at most images + 8)"

# A reference rendered with a light moved is not of the scene as loaded: refused with the reason.
"$glint" render --size 64x36 --spp 1 --quiet --move-light 0,0.5,0,0 --out ref-moved.exr ||
  fail "render with a light moved failed"
printf 'quit\n' >quit.txt
view --size 64x36 --reference ref-moved.exr --script quit.txt
grep -q "rendered with lights edited '0:0.5,0,0\*1', not the lights as loaded; reference not used" err.txt ||
  fail "a reference with a light moved was not refused: $(cat err.txt)"

printf 'wait 1\nfrobnicate 3\n' >bad.txt
view --script bad.txt
rc=$?
[ $rc -eq 2 ] || fail "bad script: exit $rc, expected 2"
grep -q 'bad.txt:2: unknown action' err.txt || fail "bad script line not reported: $(cat err.txt)"

# A bad value at run time is reported with its line and makes the exit status non-zero.
printf 'set max-depth banana\nquit\n' >badvalue.txt
view --size 64x36 --script badvalue.txt
rc=$?
[ $rc -eq 1 ] || fail "bad value: exit $rc, expected 1"
grep -q 'badvalue.txt:1:' err.txt || fail "bad value not reported with its line: $(cat err.txt)"

if [ $failures -ne 0 ]; then echo "test_viewer: $failures failures"; exit 1; fi
echo "test_viewer: all checks passed"
