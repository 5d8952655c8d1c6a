#!/usr/bin/env bash
# Installs what is missing, builds glint (release), and opens it on the built-in default scene.
# Extra arguments go to glint, e.g. scripts/run.sh render --png out.png
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
source "$root/scripts/deps.sh"
glint_install_deps
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release -DGLINT_TESTS=OFF >/dev/null
cmake --build "$root/build" -j"$(nproc)"
if [ $# -gt 0 ]; then
  exec "$root/build/app/glint" "$@"
fi
exec "$root/build/app/glint"
