#!/usr/bin/env bash
# Installs what is missing, builds Release, deforms the bundled teapot by the paper's lattice and
# writes out/demo.obj. The tool is build/sffd afterwards.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target sffd
mkdir -p out
build/sffd devices
build/sffd deform data/teapot.bpt -l data/teapot_lattice.npy --method classic -o out/demo.obj --stats out/demo_stats.json
build/sffd render data/teapot.bpt -l data/teapot_lattice.npy --method classic -o out/demo.png
echo "demo: wrote out/demo.obj (stats in out/demo_stats.json); the tool is build/sffd (build/sffd --help)"
