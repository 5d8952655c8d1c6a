#!/bin/sh
# Material variants in the viewer under Xvfb, through --script: --variant starts with one, the
# `variant` action switches as the panel's choice does (the scene reloads with it, the view
# stays), `default` goes back to the file's materials, an unknown name is an error and changes
# nothing. The scene (tests/data/variants.gltf): two squares, no light but in variant 'glow'.
# Usage: test_viewer_variants.sh GLINT TMPDIR KEEP_MODULES_LIB DATA_DIR
set -u
glint=$1
dir=$2/viewer_variants
keep_modules=$3
data=$4
screen=1280x720x24
. "$(dirname "$0")/viewer_harness.sh"
cp "$data/variants.gltf" . || exit 1

cat >switch.txt <<'SCRIPT'
wait 2
orbit 10 5
wait 2
stats
variant glow
wait 2
stats
variant default
wait 2
stats
variant blue
stats
quit
SCRIPT
view variants.gltf --size 160x90 --method pt --script switch.txt
rc=$?
grep '^stats ' out.txt >stats.txt
[ "$(wc -l <stats.txt)" -eq 4 ] || fail "expected 4 stats lines, got $(wc -l <stats.txt): $(cat err.txt)"
[ "$(field 1 variant)" = "-" ] || fail "starts with variant $(field 1 variant)"
[ "$(field 2 variant)" = "glow" ] || fail "after 'variant glow': $(field 2 variant)"
[ "$(field 3 variant)" = "-" ] || fail "after 'variant default': $(field 3 variant)"
[ "$(field 4 variant)" = "-" ] || fail "an unknown variant changed it to $(field 4 variant)"
# Unlit but in the glowing variant.
awk -v a="$(field 1 mean)" -v b="$(field 2 mean)" -v c="$(field 3 mean)" 'BEGIN { exit !(a == 0 && b > 0.01 && c == 0) }' ||
  fail "mean luminance $(field 1 mean), $(field 2 mean), $(field 3 mean): expected 0, lit, 0"
# The view stays through the switches (the orbit before them included).
[ "$(field 1 cam)" = "$(field 2 cam)" ] && [ "$(field 2 cam)" = "$(field 3 cam)" ] ||
  fail "the camera moved: $(field 1 cam), $(field 2 cam), $(field 3 cam)"
grep -q "no material variant 'blue'" err.txt || fail "no error for the unknown variant: $(cat err.txt)"
[ $rc -ne 0 ] || fail "a script with an error exited 0"

# --variant starts with it; an unknown one is one line of error before any window.
cat >start.txt <<'SCRIPT'
wait 1
stats
quit
SCRIPT
view variants.gltf --size 160x90 --variant red --script start.txt || fail "--variant red: exited $?: $(cat err.txt)"
grep '^stats ' out.txt >stats.txt
[ "$(field 1 variant)" = "red" ] || fail "--variant red starts with $(field 1 variant)"
view variants.gltf --variant blue --script start.txt
[ $? -eq 1 ] || fail "--variant blue: exit code"
[ "$(grep -c 'glint: error: variants.gltf: no material variant' err.txt)" -eq 1 ] || fail "--variant blue: $(cat err.txt)"

[ $failures -eq 0 ] && echo "test_viewer_variants: passed"
[ $failures -eq 0 ]
