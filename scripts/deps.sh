#!/usr/bin/env bash
# Installs the Debian 12 packages glint needs, when any is missing. Sourced by run.sh and test.sh.
# slurm-wlm and munge are for the test that stands up a one-node Slurm cluster (tests/test_slurm.sh).
GLINT_PACKAGES=(
  build-essential cmake pkg-config
  libglfw3-dev libembree-dev libopenexr-dev libtinygltf-dev nlohmann-json3-dev
  libimgui-dev libstb-dev libgl-dev libcjson-dev libcairo2-dev fonts-dejavu-core
  xvfb xauth xdotool x11-xserver-utils embree-tools openexr clang-format
  clang libclang-rt-14-dev
  slurm-wlm munge
)
# Opt-in, large: Blender (with the numpy its glTF importer needs) for the comparison against
# Cycles (tests/bench/blender_twin.py, the blender ctest).
if [ "${GLINT_BLENDER:-}" = 1 ]; then GLINT_PACKAGES+=(blender python3-numpy); fi

glint_install_deps() {
  local missing=()
  for p in "${GLINT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "glint: installing missing packages: ${missing[*]}"
  local cmd=(apt-get install -y --no-install-recommends "${missing[@]}")
  if [ "$(id -u)" -eq 0 ]; then
    DEBIAN_FRONTEND=noninteractive apt-get update -qq && DEBIAN_FRONTEND=noninteractive "${cmd[@]}" -qq
  elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
    sudo DEBIAN_FRONTEND=noninteractive apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive "${cmd[@]}" -qq
  else
    echo "glint: error: missing packages; run as root: apt-get update && ${cmd[*]}" >&2
    return 1
  fi
}
