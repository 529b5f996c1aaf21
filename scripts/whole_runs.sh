#!/usr/bin/env bash
# The whole `sffd deform` of the teapot (issue 13's "whole run" target, docs/PERFORMANCE.md) for two builds,
# run alternately so that the machine's noise hits both alike: RUNS runs of each build per backend (cpu,
# vulkan, gl) on the system's Mesa, and of vulkan and gl on Mesa 25.0 (scripts/mesa.sh); wall time in ms
# from the start of the process to its end, median and quartiles, and the median of its CPU time (user and
# system, all threads: what the machine's cores share, less hit by its load). Each build is a folder holding `sffd` and
# its `libsffd.so.0` (`cp build/sffd build/libsffd.so.0* DIR`).
#   scripts/whole_runs.sh BASE_DIR HEAD_DIR [RUNS]     (RUNS: 25)
# Each build's output replaces the one its last run wrote (t_base.ply, t_head.ply), as a user's repeated
# command does; one name for both made each run replace a file the other build had just written, whose
# eviction could cost the rename as much as the change measured (docs/performance/whole_run.md,
# "Output files replaced without a flush"). FRESH=1 writes a new name each run instead.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: scripts/whole_runs.sh BASE_DIR HEAD_DIR [RUNS]" >&2; exit 2; }
BASE=$(realpath "$1") HEAD=$(realpath "$2") RUNS=${3:-25}
for b in "$BASE" "$HEAD"; do [ -x "$b/sffd" ] || { echo "sffd: error: $b/sffd: no such program" >&2; exit 2; }; done
source scripts/model_set.sh
export LIBGL_ALWAYS_SOFTWARE=1
scripts/mesa.sh fetch > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "== load $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$BASE" "$HEAD" "$RUNS" "$D/$TEAPOT" "$D/lattices/$TEAPOT_L" "$tmp" "$PWD/scripts/mesa.sh" "${FRESH:-0}" <<'EOF'
import os, resource, statistics, subprocess, sys, time
base, head, runs, mesh, lattice, tmp, mesa, fresh = sys.argv[1:9]
runs, fresh = int(runs), fresh == "1"
builds = {"base": base, "head": head}
for mesa_name, backends in (("system", ("cpu", "vulkan", "gl")), ("25.0", ("vulkan", "gl"))):
    for backend in backends:
        walls, cpus = {k: [] for k in builds}, {k: [] for k in builds}
        for i in range(runs):
            for name, d in builds.items():
                out = os.path.join(tmp, f"t{i}.ply" if fresh else f"t_{name}.ply")
                cmd = ([mesa, "run", "--"] if mesa_name != "system" else []) + [
                    os.path.join(d, "sffd"), "deform", mesh, "-l", lattice, "--normalize", "0.9090909090909091",
                    "--edge-length", "0.2", "-o", out, "--binary", "--backend", backend, "--quiet"]
                t, r = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
                subprocess.run(cmd, check=True, env=dict(os.environ, LD_LIBRARY_PATH=d))
                walls[name].append(1000 * (time.perf_counter() - t))
                u = resource.getrusage(resource.RUSAGE_CHILDREN)
                cpus[name].append(1000 * (u.ru_utime + u.ru_stime - r.ru_utime - r.ru_stime))
                if fresh: os.remove(out)
        for name, w in walls.items():
            q = statistics.quantiles(w, n=4)
            print(f"mesa-{mesa_name} {backend:6s} {name}: median {statistics.median(w):6.1f} ms  "
                  f"(quartiles {q[0]:.1f} .. {q[2]:.1f}, min {min(w):.1f}, {runs} runs; "
                  f"CPU median {statistics.median(cpus[name]):.0f} ms)", flush=True)
EOF
echo "== load $(cut -d' ' -f1-3 /proc/loadavg)"
