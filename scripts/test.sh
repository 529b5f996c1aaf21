#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test with ctest; the exit status is the verdict.
#   scripts/test.sh              Release build in build/
#   scripts/test.sh --sanitize   AddressSanitizer + UndefinedBehaviorSanitizer build in build-sanitize/
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh

build=build
# The Python package too (python/, built for Debian's interpreter; docs/PYTHON.md).
flags=(-DCMAKE_BUILD_TYPE=Release -DSFFD_BUILD_PYTHON=ON -DPython_EXECUTABLE=/usr/bin/python3)
sanitize=0
if [ "${1:-}" = "--sanitize" ]; then
  sanitize=1
  build=build-sanitize
  flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DSFFD_SANITIZE=ON)
  # Leak checking is off for the ctest run: Mesa's drivers (lavapipe, llvmpipe, OSMesa) leak a few
  # allocations at exit from code unloaded by then, which no suppression can name. It is on for the
  # core tests below (no driver loaded) and for the robustness tests' refused inputs (docs/ROBUSTNESS.md).
  export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
fi

cmake -S . -B "$build" -G Ninja "${flags[@]}" >/dev/null
cmake --build "$build" -j"$(nproc)"
# Software devices only, so the verdict is the same on every machine; a virtual X server lets the
# GLFW window context be tested too. -noreset: by default the X server resets whenever its last client
# disconnects, and a test connecting during that reset fails with "cannot open display" (the rare
# GlGlfw.HiddenWindowContextRunsKernels failures of parallel runs).
export LIBGL_ALWAYS_SOFTWARE=1 VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
export VK_ICD_FILENAMES=$VK_DRIVER_FILES
xvfb-run -a -s "-screen 0 640x480x24 -noreset" ctest --test-dir "$build" --output-on-failure -j"$(nproc)"
if [ "$sanitize" = 0 ]; then
  # The Python package's tests (seconds), on the module just built in build/python.
  PYTHONPATH="$build/python" SFFD_CLI="$build/sffd" /usr/bin/python3 -m pytest -q -p no:cacheprovider python/tests
fi
if [ "$sanitize" = 1 ]; then
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 "$build/tests/sffd_core_tests" --gtest_brief=1
fi
