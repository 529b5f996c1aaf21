#!/usr/bin/env bash
# Regenerates the error tables of docs/ACCURACY.md: the paper's Tables 3 to 6 cases (cube2 with
# cube2_control_points5, the teapot t.bpt with t_control_points1; l = 0.2, level 10, below), improved
# (regular) against 2015 (knot-box) clipping, and the l sweep. Needs a built build/sffd.
set -euo pipefail
cd "$(dirname "$0")/.."
SFFD=${SFFD:-build/sffd}
source scripts/model_set.sh   # D, TEAPOT, CUBE, SPHERE, BIG and their lattices
source scripts/matplotlib.sh
row() {  # label mesh lattice normalize clip l
  "$SFFD" error "$D/$2" -l "$D/lattices/$3" --normalize "$4" --clip "$5" --edge-length "$6" --tess 10 --backend cpu --json --quiet \
    | /usr/bin/python3 -c "
import json, sys
j = json.load(sys.stdin); g = j['geometry']; n = j['normal_deg']; v = j.get('volume')
vol = '%.5g / %.5g (%.2e)' % (v['result'], v['reference'], v['rel_error']) if v else '-'
print('| $1 | $5 | $6 | %.3g / %.3g | %.3g / %.3g | %s |' % (g['avg'], g['max'], n['avg'], n['max'], vol))"
}
echo "| case | clipping | l | geometry avg / max | normal avg / max (deg) | volume result / reference (rel) |"
echo "|---|---|---|---|---|---|"
row "$CUBE + $CUBE_L (0.99)" "$CUBE" "$CUBE_L" 0.99 regular 0.2
row "$CUBE + $CUBE_L (0.99)" "$CUBE" "$CUBE_L" 0.99 knot-box 0.2
row "$TEAPOT + $TEAPOT_L (1/1.1)" "$TEAPOT" "$TEAPOT_L" 0.9090909090909091 regular 0.2
row "$TEAPOT + $TEAPOT_L (1/1.1)" "$TEAPOT" "$TEAPOT_L" 0.9090909090909091 knot-box 0.2
echo
echo "l sweep (teapot, regular clipping): l, sub-triangles, geometry avg, geometry max, normal avg, normal max"
SWEEP=$(mktemp)
for l in 0.4 0.3 0.2 0.15 0.1 0.07 0.05 0.035 0.025; do
  "$SFFD" error "$D/$TEAPOT" -l "$D/lattices/$TEAPOT_L" --normalize 0.9090909090909091 --edge-length $l --backend cpu --json --quiet \
    | /usr/bin/python3 -c "
import json, sys
j = json.load(sys.stdin); print($l, j.get('sub_triangles', 0), j['geometry']['avg'], j['geometry']['max'], j['normal_deg']['avg'], j['normal_deg']['max'])"
done | tee "$SWEEP"
# The plot of docs/ACCURACY.md.
/usr/bin/python3 - "$SWEEP" docs/figures/l_sweep_teapot.png "$TEAPOT + $TEAPOT_L" <<'PY'
import sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = [list(map(float, l.split())) for l in open(sys.argv[1]) if l.strip()]
l = [r[0] for r in rows]
fig, ax = plt.subplots(1, 2, figsize=(9, 3.4), dpi=100)
ax[0].plot(l, [r[2] for r in rows], "o-", label="geometry avg")
ax[0].plot(l, [r[3] for r in rows], "s-", label="geometry max")
ax[0].set_xlabel("edge length l"); ax[0].set_ylabel("distance to exact FFD"); ax[0].set_yscale("log"); ax[0].legend(fontsize=8)
ax2 = ax[1]
ax2.plot(l, [r[1] for r in rows], "o-", color="tab:green")
ax2.set_xlabel("edge length l"); ax2.set_ylabel("sub-triangles"); ax2.set_yscale("log")
fig.suptitle("teapot " + sys.argv[3] + ", smooth FFD, level 10")
fig.tight_layout()
fig.savefig(sys.argv[2])
PY
rm -f "$SWEEP"
