#!/usr/bin/env bash
# The issue-13 figures of two builds side by side (docs/performance/targets.md): on a shared,
# noisy machine only builds run alternately in one script can be compared. Each build is a folder
# holding `sffd` and its `libsffd.so.0` (copy them out of a build tree: `cp build/sffd build/libsffd.so.0* DIR`).
#   scripts/side_by_side.sh BASE_DIR HEAD_DIR
# Prints, for each build in turn: `sffd bench` stage medians on the system's Mesa (vulkan, gl, cpu) and on
# Mesa 25.0 (scripts/mesa.sh; vulkan, gl), two rounds of --repeat 20; five whole `sffd deform` runs per
# backend (wall s, peak RSS KB, host phases); two cold first dispatches per Mesa and backend (empty shader
# cache; wall ms, process CPU s, each kernel's first dispatch). The teapot of the model set (model_set.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -eq 2 ] || { echo "usage: scripts/side_by_side.sh BASE_DIR HEAD_DIR" >&2; exit 2; }
BASE=$(realpath "$1") HEAD=$(realpath "$2")
for b in "$BASE" "$HEAD"; do [ -x "$b/sffd" ] || { echo "sffd: error: $b/sffd: no such program" >&2; exit 2; }; done
source scripts/model_set.sh
T=$D/$TEAPOT L=$D/lattices/$TEAPOT_L
A=(--normalize 0.9090909090909091 --edge-length 0.2)
export LIBGL_ALWAYS_SOFTWARE=1 SFFD_DEVICE_TIMEOUT=${SFFD_DEVICE_TIMEOUT:-600}
scripts/mesa.sh fetch > /dev/null
MESA25=("$PWD/scripts/mesa.sh" run --)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
load() { echo "== load $(cut -d' ' -f1-3 /proc/loadavg)"; }
run() {  # BUILD [PREFIX...] :: ARGS...: the build's sffd (its library first) run by PREFIX
  local b=$1; shift
  local prefix=()
  while [ "$1" != :: ]; do prefix+=("$1"); shift; done
  shift
  LD_LIBRARY_PATH=$b "${prefix[@]}" "$b/sffd" "$@"
}
medians='import json,sys
d=json.load(sys.stdin)
for r in d["runs"]: print(sys.argv[1], r["backend"], " ".join("%s=%.2f" % (k, v["median"]) for k, v in r["stages_ms"].items()))'

load
for _ in 1 2; do for b in "$BASE" "$HEAD"; do
  run "$b" :: bench "$T" -l "$L" "${A[@]}" --backends vulkan,gl,cpu --repeat 20 --json --quiet | python3 -c "$medians" "mesa-system $(basename "$b")"
done; done
for _ in 1 2; do for b in "$BASE" "$HEAD"; do
  run "$b" "${MESA25[@]}" :: bench "$T" -l "$L" "${A[@]}" --backends vulkan,gl --repeat 20 --json --quiet | python3 -c "$medians" "mesa-25.0 $(basename "$b")"
done; done
load
for _ in 1 2 3 4 5; do for b in "$BASE" "$HEAD"; do for backend in cpu vulkan gl; do
  run "$b" /usr/bin/time -o "$tmp/time" -f "%e s %M KB" :: deform "$T" -l "$L" "${A[@]}" -o "$tmp/t.ply" --binary \
    --backend $backend --quiet --stats "$tmp/s.json"
  python3 -c 'import json,sys
h=json.load(open(sys.argv[1]))["host_ms"]
print("whole", sys.argv[2], sys.argv[3], open(sys.argv[4]).read().strip(), " ".join("%s=%.0f" % kv for kv in h.items()))' \
    "$tmp/s.json" "$(basename "$b")" $backend "$tmp/time"
done; done; done
load
for mesa in system 25.0; do for backend in vulkan gl; do for _ in 1 2; do for b in "$BASE" "$HEAD"; do
  prefix=(); [ $mesa = system ] || prefix=("${MESA25[@]}")
  MESA_SHADER_CACHE_DISABLE=true SFFD_SHADER_CACHE_DISABLE=1 SFFD_TRACE_COMPILE=1 run "$b" /usr/bin/time -o "$tmp/time" -f "%U %S" "${prefix[@]}" :: \
    bench "$T" -l "$L" "${A[@]}" --backends $backend --repeat 1 --warmup 0 --json --quiet > "$tmp/c.json" 2> "$tmp/c.err"
  python3 -c 'import json,sys
r=json.load(open(sys.argv[1]))["runs"][0]; u,s=open(sys.argv[2]).read().split()
print("cold", sys.argv[3], sys.argv[4], sys.argv[5], "%.0f ms" % r["cold_first_dispatch_ms"], "cpu %.2f s" % (float(u) + float(s)), end=" ")' \
    "$tmp/c.json" "$tmp/time" "$(basename "$b")" "mesa-$mesa" $backend
  grep "first dispatch" "$tmp/c.err" | sed 's/sffd: first dispatch //' | tr '\n' ' '; echo
done; done; done; done
load
