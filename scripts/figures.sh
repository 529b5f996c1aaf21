#!/usr/bin/env bash
# Regenerates the figures and tables of docs/ACCURACY.md (clipping quality). Needs a built build/sffd
# (scripts/demo.sh or scripts/test.sh) and Debian's python3-matplotlib (installed when missing).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/matplotlib.sh
SFFD=${SFFD:-build/sffd}
source scripts/model_set.sh   # D, TEAPOT, CUBE, SPHERE, BIG and their lattices
T=$(mktemp -d)
mkdir -p docs/figures
run() {  # name mesh lattice clip l
  "$SFFD" clip "$D/$2" -l "$D/lattices/$3" --clip "$4" --edge-length "$5" --backend cpu -o "$T/$1.obj" --stats "$T/$1.json" --quiet
}
echo "$BIG_MESH + $BIG_L (5x5x5 degree 2), mesh normalised to 0.99:"
run rabbit_kb "$BIG_MESH" "$BIG_L" knot-box 0.2
run rabbit_r02 "$BIG_MESH" "$BIG_L" regular 0.2
run rabbit_r005 "$BIG_MESH" "$BIG_L" regular 0.05
/usr/bin/python3 tools/plot_quality.py "docs/figures/clip_quality_$BIG.png" "$BIG_MESH: sub-triangle quality" \
  "knot-box=$T/rabbit_kb.json" "regular l=0.2=$T/rabbit_r02.json" "regular l=0.05=$T/rabbit_r005.json"
echo "$SPHERE + $SPHERE_L:"
run sphere_kb "$SPHERE" "$SPHERE_L" knot-box 0.2
run sphere_r02 "$SPHERE" "$SPHERE_L" regular 0.2
run sphere_r01 "$SPHERE" "$SPHERE_L" regular 0.1
/usr/bin/python3 tools/plot_quality.py docs/figures/clip_quality_sphere.png "sphere.obj: sub-triangle quality" \
  "knot-box=$T/sphere_kb.json" "regular l=0.2=$T/sphere_r02.json" "regular l=0.1=$T/sphere_r01.json"
echo "$CUBE + $CUBE_L:"
run cube_kb "$CUBE" "$CUBE_L" knot-box 0.2
run cube_r02 "$CUBE" "$CUBE_L" regular 0.2
/usr/bin/python3 tools/plot_quality.py docs/figures/clip_quality_cube2.png "cube2.obj: sub-triangle quality" \
  "knot-box=$T/cube_kb.json" "regular l=0.2=$T/cube_r02.json"
rm -rf "$T"
