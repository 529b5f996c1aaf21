#!/usr/bin/env bash
# A second, newer Mesa (25.0 from Debian's bookworm-backports), unpacked into the build tree and never
# installed: lavapipe (Vulkan) and llvmpipe (GL through EGL) of that generation, for benchmarks and the
# conformance run on both driver generations (docs/PERFORMANCE.md, docs/CONFORMANCE.md).
#   scripts/mesa.sh fetch            download and unpack once (quick when already there); prints the folder
#   scripts/mesa.sh run -- CMD...    run CMD with the Vulkan loader, EGL and the dynamic linker pointed there
#   scripts/mesa.sh env              print the export lines (eval "$(scripts/mesa.sh env)")
# MESA_VERSION pins the Debian version; MESA_DIR the folder (default build/mesa-25.0). OSMesa stays the
# system's (25.1 drops it; gl-osmesa on both runs is the 22.3 one).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
MESA_VERSION=${MESA_VERSION:-25.0.7-2~bpo12+1}
MESA_DIR=${MESA_DIR:-$root/build/mesa-25.0}
MESA_DIR=$(mkdir -p "$MESA_DIR" && cd "$MESA_DIR" && pwd)
lib=$MESA_DIR/root/usr/lib/x86_64-linux-gnu
stamp=$MESA_DIR/.complete-$MESA_VERSION

die() { echo "sffd: error: scripts/mesa.sh: $*" >&2; exit 1; }

fetch() {
  [ -e "$stamp" ] && return 0
  # The mirror the system already uses, with its backports suite; apt state private to this folder.
  local uri
  uri=$(awk '/^URIs:/ {print $2; exit}' /etc/apt/sources.list.d/debian.sources 2>/dev/null || true)
  [ -n "$uri" ] || uri=http://deb.debian.org/debian
  local apt=$MESA_DIR/apt
  rm -rf "$apt" "$MESA_DIR/root" "$MESA_DIR"/*.deb
  mkdir -p "$apt/lists/partial" "$apt/archives/partial" "$MESA_DIR/root"
  echo "deb $uri bookworm-backports main" > "$apt/sources.list"
  local opts=(-o Dir::Etc::sourcelist="$apt/sources.list" -o Dir::Etc::sourceparts=/dev/null
              -o Dir::State::Lists="$apt/lists" -o Dir::Cache="$apt/cache" -o Debug::NoLocking=1
              -o APT::Sandbox::User=root)
  mkdir -p "$apt/cache/archives/partial"
  apt-get "${opts[@]}" -qq update || die "apt-get update of bookworm-backports failed"
  # libdrm: the newest the suite has (25.0 needs a newer one than bookworm's).
  local drm
  drm=$(apt-cache "${opts[@]}" madison libdrm2 | awk -F'|' '/bpo12/ {gsub(/ /,"",$2); print $2; exit}')
  [ -n "$drm" ] || die "no libdrm2 in bookworm-backports"
  local pkgs=() p
  for p in mesa-vulkan-drivers libgl1-mesa-dri mesa-libgallium libgbm1 libegl-mesa0 libglx-mesa0; do
    pkgs+=("$p=$MESA_VERSION")
  done
  pkgs+=("libdrm2=$drm" "libdrm-amdgpu1=$drm")
  (cd "$MESA_DIR" && apt-get "${opts[@]}" -qq download "${pkgs[@]}") ||
    die "apt-get download ${pkgs[*]} failed (is $MESA_VERSION still in bookworm-backports? set MESA_VERSION)"
  local deb
  for deb in "$MESA_DIR"/*.deb; do dpkg -x "$deb" "$MESA_DIR/root"; done
  rm -f "$MESA_DIR"/*.deb
  [ -e "$lib/libvulkan_lvp.so" ] && [ -e "$lib/libEGL_mesa.so.0" ] || die "the packages lack lavapipe or EGL"
  # Loader files naming the unpacked libraries by absolute path.
  sed "s|\"library_path\" *: *\"[^\"]*\"|\"library_path\": \"$lib/libvulkan_lvp.so\"|" \
    "$MESA_DIR"/root/usr/share/vulkan/icd.d/lvp_icd*.json > "$MESA_DIR/lvp_icd.json"
  sed "s|\"library_path\" *: *\"[^\"]*\"|\"library_path\": \"$lib/libEGL_mesa.so.0\"|" \
    "$MESA_DIR/root/usr/share/glvnd/egl_vendor.d/50_mesa.json" > "$MESA_DIR/egl_mesa.json"
  touch "$stamp"
}

env_lines() {
  echo "export VK_DRIVER_FILES=$MESA_DIR/lvp_icd.json VK_ICD_FILENAMES=$MESA_DIR/lvp_icd.json"
  echo "export __EGL_VENDOR_LIBRARY_FILENAMES=$MESA_DIR/egl_mesa.json"
  echo "export LD_LIBRARY_PATH=$lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  echo "export LIBGL_DRIVERS_PATH=$lib/dri"
}

case "${1:-}" in
  fetch) fetch; echo "$MESA_DIR" ;;
  env) fetch; env_lines ;;
  run)
    shift
    [ "${1:-}" = "--" ] && shift
    [ $# -gt 0 ] || die "usage: scripts/mesa.sh run -- CMD..."
    fetch
    eval "$(env_lines)"
    exec "$@" ;;
  *) echo "usage: scripts/mesa.sh fetch | env | run -- CMD..." >&2; exit 2 ;;
esac
