# The viewer benchmarks' X server, sourced by viewer_motion.sh and viewer_display.sh: xvfb_start
# DIR starts Xvfb on a display it picks itself (-displayfd), 1920x1080, its files in DIR, sets
# DISPLAY and xvfb_pid, and stops it when the script exits (DIR is removed then when
# xvfb_remove_dir is set). Fails when Xvfb is missing or does not start.
xvfb_start() {
  command -v Xvfb >/dev/null || { echo "Xvfb not installed"; return 1; }
  Xvfb -displayfd 3 -screen 0 1920x1080x24 -nolisten tcp 3>"$1/display.txt" 2>"$1/xvfb.log" &
  xvfb_pid=$!
  xvfb_dir=$1
  trap 'kill $xvfb_pid 2>/dev/null; wait $xvfb_pid 2>/dev/null; [ -z "${xvfb_remove_dir:-}" ] || rm -rf "$xvfb_dir"' EXIT
  tries=0
  until [ -s "$1/display.txt" ]; do
    tries=$((tries + 1))
    [ $tries -le 300 ] && kill -0 $xvfb_pid 2>/dev/null || { echo "Xvfb did not start: $(cat "$1/xvfb.log")"; return 1; }
    sleep 0.1
  done
  DISPLAY=":$(head -n 1 "$1/display.txt")"
  export DISPLAY
}
