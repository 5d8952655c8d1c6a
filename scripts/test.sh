#!/usr/bin/env bash
# Installs what is missing, builds the test configuration (AddressSanitizer + UndefinedBehavior-
# Sanitizer) and runs the whole suite with CTest. Extra arguments go to ctest (e.g. -R loader).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
source "$root/scripts/deps.sh"
glint_install_deps
build="$root/build-test"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGLINT_SANITIZE=ON -DGLINT_TESTS=ON >/dev/null
cmake --build "$build" -j"$(nproc)"
cd "$build"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --output-on-failure -j"$(nproc)" "$@"
