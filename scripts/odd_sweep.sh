#!/usr/bin/env bash
# The repository's odd-but-valid meshes (tests/data/bad/odd) through every backend, method and option
# set at several tessellation levels, as a user would run them: each lattice fitted to its mesh and
# twisted, each `sffd deform` into a binary PLY. Prints every run that does not exit 0 and a count;
# exit 1 if any did. RobustOdd (tests/robustness_test.cc) runs a subset of this in CI, at --tess 3.
#   scripts/odd_sweep.sh [SFFD] [LEVELS]      (SFFD: build/sffd; LEVELS: "1 2 4 7")
set -uo pipefail
cd "$(dirname "$0")/.."
S=$(realpath "${1:-build/sffd}") LEVELS=${2:-1 2 4 7}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
configs=("--method smooth" "--method smooth --clip knot-box" "--method smooth --split" "--method smooth --strict"
         "--method smooth --precision double" "--method accurate" "--method accurate --strict --precision double"
         "--method classic")
runs=0 failed=0
for m in tests/data/bad/odd/*.{obj,ply,off,stl,om}; do
  n=$(basename "$m")
  if ! "$S" lattice "$m" -o "$W/L.json" --preset twist:0.5 --quiet 2> "$W/err"; then
    echo "lattice $n: $(head -c 300 "$W/err")"; failed=$((failed + 1)); continue
  fi
  for b in cpu vulkan gl; do
    for cfg in "${configs[@]}"; do
      for t in $LEVELS; do
        runs=$((runs + 1))
        # shellcheck disable=SC2086
        "$S" deform "$m" -l "$W/L.json" --backend $b --tess "$t" $cfg -o "$W/out.ply" --binary --quiet 2> "$W/err" ||
          { echo "$n --backend $b --tess $t $cfg: exit $?: $(head -c 300 "$W/err")"; failed=$((failed + 1)); }
      done
    done
  done
done
echo "odd_sweep: $runs runs, $failed failed"
[ "$failed" = 0 ]
