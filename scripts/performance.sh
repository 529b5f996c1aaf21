#!/usr/bin/env bash
# Regenerates the figures of docs/performance/stages.md and scaling.md with `sffd bench`: the per-stage tables (the paper's
# Tables 1 and 2) for the benchmark model set on each backend, and the scaling plots (time against
# faces, against l, against the tessellation level). Needs a built build/sffd; writes the raw JSON to
# out/perf/ and the plots to docs/figures/perf_*.png; prints the tables as Markdown.
#   scripts/performance.sh            all of it (about 10 minutes on 2 cores)
#   REPEAT=5 BACKENDS=vulkan,gl,cpu   the defaults
#   ONLY=tess                         rerun one group (models, faces, l, tess), then redo the tables and plots
#   MESA=system|25.0|both             which Mesa generation: the system's (22.3 on Debian 12), the pinned 25.0
#                                     of scripts/mesa.sh (JSON under out/perf/mesa-25.0/), or both side by side
set -euo pipefail
cd "$(dirname "$0")/.."
SFFD=${SFFD:-build/sffd}
REPEAT=${REPEAT:-5}
BACKENDS=${BACKENDS:-vulkan,gl,cpu}
source scripts/model_set.sh   # D, TEAPOT, CUBE, SPHERE, BIG and their lattices
export BIG
source scripts/matplotlib.sh
OUT=out/perf
mkdir -p "$OUT" docs/figures

ONLY=${ONLY:-}
MESA=${MESA:-system}
case "$MESA" in
  system) gens=(system) ;;
  25.0) gens=(25.0) ;;
  both) gens=(system 25.0) ;;
  *) echo "sffd: error: MESA must be system, 25.0 or both" >&2; exit 2 ;;
esac
[ "$MESA" = system ] || { scripts/mesa.sh fetch >/dev/null; mkdir -p "$OUT/mesa-25.0"; }
# A cold shader cache makes the first dispatch of a deform kernel long on lavapipe 25.0 (docs "Cold start").
export SFFD_DEVICE_TIMEOUT=${SFFD_DEVICE_TIMEOUT:-600}
want() { [ -z "$ONLY" ] || [ "$ONLY" = "$1" ]; }
bench() {  # name mesh lattice normalize l tess [extra...]
  local name=$1 mesh=$2 lat=$3 norm=$4 l=$5 tess=$6 gen
  shift 6
  local args=(bench "$D/$mesh" -l "$D/lattices/$lat" --normalize "$norm" --edge-length "$l" --tess "$tess"
              --backends "$BACKENDS" --repeat "$REPEAT" --json --quiet "$@")
  for gen in "${gens[@]}"; do
    if [ "$gen" = system ]; then "$SFFD" "${args[@]}" > "$OUT/$name.json"
    else scripts/mesa.sh run -- "$SFFD" "${args[@]}" > "$OUT/mesa-$gen/$name.json"; fi
  done
}

# The benchmark model set (docs/PERFORMANCE.md "Models"): 5x5x5 degree-2 lattices, level 10.
if want models; then
bench teapot "$TEAPOT" "$TEAPOT_L" 0.9090909090909091 0.2 10
bench teapot_split "$TEAPOT" "$TEAPOT_L" 0.9090909090909091 0.2 10 --split
bench "$BIG" "$BIG_MESH" "$BIG_L" 0.99 0.2 10
bench sphere "$SPHERE" "$SPHERE_L" 0.99 0.2 10
bench teapot47k "$TEAPOT" "$TEAPOT_L" 0.9090909090909091 0.2 10 --bpt-resolution 26
fi

# Scaling: faces (the teapot at finer grids; l = 0.2 gives one sub-triangle a face), l, level.
want faces && for r in 4 8 16 26 53 80; do bench faces_$r "$TEAPOT" "$TEAPOT_L" 0.9090909090909091 0.2 10 --bpt-resolution $r; done
want l && for l in 0.4 0.2 0.1 0.05; do bench l_$l "$TEAPOT" "$TEAPOT_L" 0.9090909090909091 $l 10; done
want tess && for n in 1 2 5 10 20 40; do bench tess_$n "$TEAPOT" "$TEAPOT_L" 0.9090909090909091 0.2 $n; done

/usr/bin/python3 - "$OUT" "${gens[@]}" <<'PY'
import json, os, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
out, gens = sys.argv[1], sys.argv[2:]
gen_dir = lambda g: out if g == "system" else os.path.join(out, "mesa-" + g)
load_gen = lambda g, n: json.load(open(os.path.join(gen_dir(g), n + ".json")))
load = lambda n: load_gen(gens[0], n)
med = lambda run, k: run["stages_ms"][k]["median"]
# A group not measured yet (ONLY= on a fresh clone) is left out of the tables and plots, not an error.
have = lambda n, g=None: os.path.exists(os.path.join(gen_dir(g or gens[0]), n + ".json"))

for g in gens:
    print("Mesa: %s" % g)
    print("| model | input tris | sub-tris | output tris | backend | driver | PN ms | clip ms | deform ms | cold first run ms | peak RSS MiB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for n in ["teapot", os.environ["BIG"], "sphere", "teapot47k"]:
        if not have(n, g): continue
        j = load_gen(g, n)
        for r in j["runs"]:
            print("| %s | %d | %d | %d | %s | %s | %.2f | %.2f | %.2f | %.0f | %.0f |" % (
                n, j["input_triangles"], j["sub_triangles"], j["output_triangles"], r["backend"], r.get("driver", ""),
                med(r, "pn"), med(r, "clip"), med(r, "deform"), r["cold_first_dispatch_ms"], r["peak_rss_mb"]))
    print()
if len(gens) == 2 and have("teapot", gens[0]) and have("teapot", gens[1]):   # the teapot on both generations, side by side (same binary, same run of this script)
    print("| backend | PN ms %s / %s | clip ms | deform ms | cold first run ms |" % tuple(gens))
    print("|---|---|---|---|---|")
    a, b = load_gen(gens[0], "teapot"), load_gen(gens[1], "teapot")
    for ra, rb in zip(a["runs"], b["runs"]):
        print("| %s | %s |" % (ra["backend"], " | ".join("%.2f / %.2f" % (med(ra, k), med(rb, k)) for k in ["pn", "clip", "deform"]))
              + " %.0f / %.0f |" % (ra["cold_first_dispatch_ms"], rb["cold_first_dispatch_ms"]))
    print()
j = load("teapot_split") if have("teapot_split") else {"runs": []}
print("| backend | deform.sample | deform.fit | deform.adjust | deform.tessellate | sum |")
print("|---|---|---|---|---|---|")
for r in j["runs"]:
    steps = [k for k in ["deform.sample", "deform.fit", "deform.adjust", "deform.tessellate"] if k in r["stages_ms"]]
    if steps:
        print("| %s | %s | %.2f |" % (r["backend"], " | ".join("%.2f" % med(r, k) for k in steps), med(r, "deform")))

def sweep(names, xkey, xlabel, png, title, logx=True):
    if not all(have(n) for n in names): return print("(%s: not all of %s measured, plot left as it was)" % (png, names[0]))
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.6), dpi=100)
    data = [load(n) for n in names]
    for b in [r["backend"] for r in data[0]["runs"]]:
        xs, pre, de = [], [], []
        for j in data:
            r = next(r for r in j["runs"] if r["backend"] == b)
            xs.append(xkey(j)); pre.append(med(r, "pn") + med(r, "clip")); de.append(med(r, "deform"))
        ax[0].plot(xs, pre, "o-", label=b)
        ax[1].plot(xs, de, "o-", label=b)
    for a, t in zip(ax, ["pre-compute (PN + clip)", "deform stage"]):
        a.set_xlabel(xlabel); a.set_ylabel("ms (median)"); a.set_title(t, fontsize=10)
        a.set_yscale("log")
        if logx: a.set_xscale("log")
        a.grid(True, which="both", alpha=0.3); a.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(png)

sweep(["faces_%d" % r for r in [4, 8, 16, 26, 53, 80]], lambda j: j["input_triangles"], "input triangles (l = 0.2: one sub-triangle each, a few more below 5k)",
      "docs/figures/perf_faces.png", "teapot at finer grids, l = 0.2, level 10")
sweep(["l_%s" % l for l in ["0.4", "0.2", "0.1", "0.05"]], lambda j: j["sub_triangles"], "sub-triangles (l = 0.4, 0.2, 0.1, 0.05)",
      "docs/figures/perf_l.png", "teapot, l sweep, level 10")
sweep(["tess_%d" % n for n in [1, 2, 5, 10, 20, 40]], lambda j: j["output_triangles"], "output triangles (level 1, 2, 5, 10, 20, 40)",
      "docs/figures/perf_tess.png", "teapot, l = 0.2, tessellation level sweep")
print()
print("sweeps (backend: x -> pre-compute ms, deform ms):")
for group in [["faces_%d" % r for r in [4, 8, 16, 26, 53, 80]], ["l_%s" % l for l in ["0.4", "0.2", "0.1", "0.05"]],
              ["tess_%d" % n for n in [1, 2, 5, 10, 20, 40]]]:
    for n in filter(have, group):
        j = load(n)
        print(n, j["input_triangles"], j["sub_triangles"], j["output_triangles"],
              " ".join("%s %.2f %.2f" % (r["backend"], med(r, "pn") + med(r, "clip"), med(r, "deform")) for r in j["runs"]))
PY
