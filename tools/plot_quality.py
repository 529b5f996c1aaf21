#!/usr/bin/python3
"""Quality histogram of regular against knot-box clipping, from `sffd clip --stats` files.

usage: plot_quality.py OUT.png TITLE LABEL=STATS.json ... (the last "=" splits label and path)   (Debian's python3-matplotlib)
Prints the markdown table rows that docs/ACCURACY.md carries.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

out, title, runs = sys.argv[1], sys.argv[2], [a.rsplit("=", 1) for a in sys.argv[3:]]
fig, ax = plt.subplots(figsize=(7, 3.6), dpi=100)
width = 0.05 / (len(runs) + 0.5)
for i, (label, path) in enumerate(runs):
    s = json.load(open(path))
    q = s["quality"]
    hist = q["quality_histogram"]
    total = max(1, sum(hist))
    xs = [0.05 * b + width * (i + 0.25) for b in range(len(hist))]
    ax.bar(xs, [100.0 * h / total for h in hist], width=width, align="edge",
           label=f"{label} ({s['sub_triangles']} sub-triangles)")
    print(f"| {label} | {s['edge_length']:.4g} | {s['sub_triangles']} | {q['min_angle_deg']:.3g} | "
          f"{q['quality']['min']:.3f} | {q['quality']['p1']:.3f} | {q['quality']['median']:.3f} | "
          f"{100 * q['share_below_0_3']:.2f} % | {q['aspect_ratio']['p99']:.2f} | {q['area_ratio']['cv']:.2f} |")
ax.set_xlabel("quality 2\u221a3\u00b7inradius / longest edge (1 = equilateral)")
ax.set_ylabel("share of sub-triangles (%)")
ax.set_title(title)
ax.set_xlim(0, 1)
ax.legend(loc="upper left", fontsize=8)
fig.tight_layout()
fig.savefig(out)
