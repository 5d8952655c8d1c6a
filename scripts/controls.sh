#!/usr/bin/env bash
# Does each live control of the many-light methods visibly change SCENE? Renders both settings of
# each (same seed and frames) and counts the pixels whose tone-mapped 8-bit value differs by more
# than 8/255 (scripts/pngdiff.py): vsl with --clamp on/off and --radius-mult 1/4, vsl+hl with
# --clusters 1/4. Side-by-side images (A, B, the differing pixels) go to OUT_DIR.
#   scripts/controls.sh [SCENE] [WxH] [SPP] [OUT_DIR]   # defaults: the default scene, 480x270, 256, /tmp
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
glint=${GLINT:-$root/build/app/glint}
scene=${1:-}
size=${2:-480x270}
spp=${3:-256}
out=${4:-/tmp}
name=${scene#builtin:}
name=${name:-default}
name=${name##*/}

pair() { # LABEL METHOD OPTION VALUE_A VALUE_B
  local a="$out/controls-$name-$1-$4.png" b="$out/controls-$name-$1-$5.png"
  "$glint" render $scene --method "$2" "$3" "$4" --spp "$spp" --size "$size" --seed 1 --png "$a" --quiet
  "$glint" render $scene --method "$2" "$3" "$5" --spp "$spp" --size "$size" --seed 1 --png "$b" --quiet
  printf '%-10s %s %s vs %s: ' "$2" "$3" "$4" "$5"
  python3 "$root/scripts/pngdiff.py" "$a" "$b" --side-by-side "$out/controls-$name-$1.png"
}

pair clamp vsl --clamp on off
pair radius vsl --radius-mult 1 4
pair clusters vsl+hl --clusters 1 4
