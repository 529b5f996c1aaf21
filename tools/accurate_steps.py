#!/usr/bin/env python3
"""Times the accurate FFD kernels' three dispatches (samples, control points, tessellation) on a kept
Deformer: the medians of 5 deforms after a first, in ms (docs/performance/scaling.md, "The accurate
kernels' reads"). Needs the Python package (PYTHONPATH=build/python) and numpy.

    PYTHONPATH=build/python /usr/bin/python3 tools/accurate_steps.py MESH LATTICE [--backend vulkan] [--tess 10]
"""
import argparse
import statistics

import sffd


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("lattice")
    ap.add_argument("--backend", default="vulkan")
    ap.add_argument("--tess", type=int, default=10)
    ap.add_argument("--precision", default="float")
    a = ap.parse_args()
    vertices, triangles, _ = sffd.read_mesh(a.mesh)
    lattice = sffd.Lattice.from_file(a.lattice)
    d = sffd.Deformer(vertices, triangles, lattice, method="accurate", backend=a.backend, precision=a.precision, tess=a.tess)
    runs = []
    for i in range(6):
        d.deform(lattice)
        if i:   # the first pays for the kernels' code generation
            runs.append(dict(d.timings["steps_ms"]))
    medians = {k: round(statistics.median(r[k] for r in runs), 1) for k in runs[0]}
    print(d.device, d.sub_triangles, "sub-triangles,", medians)


if __name__ == "__main__":
    main()
