#!/usr/bin/env bash
# The one list of Debian 12 packages sffd needs to build, test and run; installs the missing ones.
# Sourced or run by scripts/demo.sh and scripts/test.sh. Quick when everything is there.
set -euo pipefail

SFFD_PACKAGES=(
  cmake g++ pkg-config ninja-build
  libosmesa6-dev libegl-dev libegl1-mesa-dev libgl-dev libgl1-mesa-dri libegl-mesa0
  mesa-vulkan-drivers libvulkan-dev vulkan-tools vulkan-validationlayers
  glslang-tools glslang-dev spirv-tools
  libglm-dev libglfw3-dev libopenmesh-dev nlohmann-json3-dev libtinygltf-dev libpng-dev python3-glad
  libgtest-dev libbenchmark-dev
  clang libclang-rt-14-dev
  xvfb xauth
  python3-dev python3-numpy python3-pytest python3-venv python3-pip python3-setuptools python3-wheel pybind11-dev
)

missing=()
for p in "${SFFD_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "sffd: installing ${#missing[@]} missing packages: ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
