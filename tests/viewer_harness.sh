# The viewer tests' shared set-up, sourced by test_viewer*.sh after they set glint, dir (their
# scratch directory), keep_modules (may be empty) and screen (Xvfb's WxHxD): a fresh scratch
# directory as the working directory, fail(), the leak-check exemptions, one X server (with the
# extra arguments xvfb_args, if set), view() to run the viewer in it, and waits for a background
# viewer's output. Exits 77 (skipped) without Xvfb.
command -v Xvfb >/dev/null || { echo "Xvfb not installed: skipped"; exit 77; }
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# Mesa's llvmpipe, X11 and xdotool keep allocations past exit; only they are exempt from leak checks.
printf 'leak:libGLX_mesa\nleak:swrast_dri\nleak:libgallium\nleak:libLLVM\nleak:libX11\nleak:libxcb\nleak:libdbus\nleak:libglfw\nleak:libGL\nleak:dri\nleak:libxdo\n' >lsan.supp
export LSAN_OPTIONS="suppressions=$dir/lsan.supp:print_suppressions=0"
# Under ASan the driver's modules must stay loaded for those names to be known (keep_modules.c);
# the ASan runtime has to come first among preloaded libraries.
asan=$(ldd "$glint" | sed -n 's/.*libasan[^ ]* => \([^ ]*\).*/\1/p')
preload=
if [ -n "$asan" ] && [ -n "$keep_modules" ]; then preload="$asan $keep_modules"; fi

# One X server for the whole script, on a display it picks itself: xvfb-run per call would replace
# the viewer's exit status with its own when its clean-up fails (exit 5), and costs a start each.
Xvfb -displayfd 3 -screen 0 "$screen" -nolisten tcp ${xvfb_args:-} 3>display.txt 2>xvfb.log &
xvfb_pid=$!
trap 'kill $xvfb_pid 2>/dev/null; wait $xvfb_pid 2>/dev/null' EXIT
tries=0
until [ -s display.txt ]; do
  tries=$((tries + 1))
  [ $tries -le 300 ] && kill -0 $xvfb_pid 2>/dev/null || { echo "Xvfb did not start: $(cat xvfb.log)"; exit 1; }
  sleep 0.1
done
export DISPLAY=":$(head -n 1 display.txt)"

view() { # view ARGS... : runs the viewer headless, stdout to out.txt, stderr to err.txt
  timeout 300 env LD_PRELOAD="$preload" "$glint" "$@" >out.txt 2>err.txt
}
# field N NAME: the value NAME= on line N of stats.txt (the script's `stats` lines).
field() { sed -n "$1p" stats.txt | tr ' ' '\n' | sed -n "s/^$2=//p"; }
below() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a < b) }'; } # below A B: A < B
# stats_lines N [TRIES]: waits (0.1 s steps) until out.txt holds N stats lines
stats_lines() {
  n=0
  while :; do
    c=$(grep -c '^stats ' out.txt 2>/dev/null) || c=0 # no file yet: none
    [ "${c:-0}" -lt "$1" ] || break
    n=$((n + 1))
    [ $n -le "${2:-1500}" ] || return 1
    sleep 0.1
  done
}
# file_made FILE: waits (0.1 s steps, at most 150 s) until FILE exists and is not empty
file_made() {
  n=0
  until [ -s "$1" ]; do
    n=$((n + 1))
    [ $n -le 1500 ] || return 1
    sleep 0.1
  done
}
# view_bg READY ARGS...: the viewer in the background (its pid in viewer) until its script has made
# the file READY; then win is its window, empty (a failure noted) when none came.
view_bg() {
  ready=$1
  shift
  rm -f "$ready" out.txt
  view "$@" &
  viewer=$!
  win=
  file_made "$ready" && win=$(xdotool search --name 'glint' | head -n 1)
  [ -n "$win" ] || fail "no viewer window for $*: $(cat err.txt)"
}
# view_end NAME FILE...: makes the FILEs the script waits for, waits for the viewer (a failure noted
# unless it exits 0) and puts its stats lines in stats.txt.
view_end() {
  name=$1
  shift
  touch "$@"
  wait $viewer
  rc=$?
  [ $rc -eq 0 ] || fail "$name exited $rc: $(cat err.txt)"
  grep '^stats ' out.txt >stats.txt
}
