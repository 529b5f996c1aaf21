#!/usr/bin/env bash
# What a machine with a GPU shows that the CPU-only CI cannot (docs/performance/gpu.md,
# docs/CONFORMANCE.md "Measured matrix"). Needs a built build/sffd (or SFFD=path) and the GPU's
# Vulkan ICD and EGL vendor where the loaders find them (VK_DRIVER_FILES, __EGL_VENDOR_LIBRARY_FILENAMES).
#   scripts/gpu_check.sh OUT_DIR [DUMP_DIR]
# DUMP_DIR: a `sffd conform --cases default --dump` made elsewhere (the CI's Mesa 22.3), checked bit for
# bit. SFFD_REFERENCE_DATA as for model_set.sh (the teapot t.bpt); TESTS=DIR also runs the gtest binaries
# of DIR (a build's tests/) and summarises them. Each step is bounded by a timeout; in order:
#   devices; the kernels' compile times with an empty driver cache (SFFD_TRACE_COMPILE, fast float,
#   strict float and strict double, Vulkan and GL); conform --cases default live (vulkan, gl-egl, gles,
#   cpu) and against DUMP_DIR; bench of the teapot (first process with an empty driver cache: cold; then
#   warm, fast and strict); five whole `deform --binary` runs per
#   backend; strict outputs of every backend cmp'ed with the CPU's (smooth, accurate; float, double);
#   a 1,000,000-triangle mesh at level 3 per backend, smooth (both clippings) and accurate (wall, peak RSS);
#   the gtest binaries.
# STEPS="compile conform bench whole strict big tests" (the default) picks steps; COMPILE_BACKENDS
# ("vulkan gl", the default) the backends of the compile step, so that two processes can time one each.
set -uo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 1 ] || { echo "usage: scripts/gpu_check.sh OUT_DIR [DUMP_DIR]" >&2; exit 2; }
OUT=$(realpath -m "$1") DUMP=${2:+$(realpath "$2")}
S=$(realpath "${SFFD:-build/sffd}")
source scripts/model_set.sh
T=$D/$TEAPOT L=$D/lattices/$TEAPOT_L
A=(--normalize 0.9090909090909091 --edge-length 0.2)
mkdir -p "$OUT"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
export SFFD_DEVICE_TIMEOUT=${SFFD_DEVICE_TIMEOUT:-120}
t0=$(date +%s)
STEPS=" ${STEPS:-compile conform bench whole strict big tests} "
want() { [[ $STEPS == *" $1 "* ]]; }
step() { echo "== [$(( $(date +%s) - t0 )) s] $*"; }
medians() {  # JSON files of `sffd bench --json`: one line per run
  python3 - "$@" <<'PY'
import json, sys
for f in sys.argv[1:]:
    for r in json.load(open(f))["runs"]:
        st = " ".join("%s %.3f" % (k, v["median"]) for k, v in r["stages_ms"].items())
        host = " ".join("%s %.3f" % (k, v["median"]) for k, v in r["host_wall_ms"].items())
        print("%s %s: cold %.0f ms; stages %s; host %s" % (f.rsplit("/", 1)[-1], r["backend"], r["cold_first_dispatch_ms"], st, host))
PY
}

step devices
{ command -v nvidia-smi > /dev/null && nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; "$S" devices; } | tee "$OUT/devices.txt"
"$S" devices --json > "$OUT/devices.json"

# NVIDIA's drivers keep compiled shaders under __GL_SHADER_DISK_CACHE_PATH (GL and Vulkan alike): a new
# folder is an empty cache.
emptyCache() { mktemp -d "$W/cache.XXXX"; }

if want compile; then
step "compiles with an empty driver cache (strict double: minutes on NVIDIA's GL before 2026-11-27)"
for b in ${COMPILE_BACKENDS:-vulkan gl}; do
  for m in fast strict strict-double; do
    case $m in fast) flag=();; strict) flag=(--strict);; strict-double) flag=(--strict --precision double);; esac
    a=$(date +%s%N)
    SFFD_TRACE_COMPILE=1 __GL_SHADER_DISK_CACHE_PATH=$(emptyCache) timeout 400 "$S" deform "$T" -l "$L" "${A[@]}" \
      --backend $b "${flag[@]}" -o "$W/c.ply" --binary --quiet > "$W/trace" 2>&1
    rc=$?
    echo "$b $m: exit $rc, $(( ($(date +%s%N) - a) / 1000000 )) ms; $(grep -o 'compile [a-z]* [a-z_]*[^:]*: [0-9.]* ms' "$W/trace" | sed 's/^compile [a-z]* //' | paste -sd';')"
  done
done | tee "$OUT/compile.txt"
fi

if want conform; then
step "conform --cases default: against DUMP (the stronger check, first), then live"
if [ -n "$DUMP" ]; then
  timeout 300 "$S" conform --cases default --against "$DUMP" --backends vulkan,gl-egl,gles,cpu --require vulkan,gl-egl \
    --json "$OUT/conform_against.json" > "$OUT/conform_against.log" 2>&1
  echo "against $DUMP: exit $?; strict comparisons not at 0 ulp: $(grep strict "$OUT/conform_against.log" | grep -vc ' max_ulp=0 ')"
  grep -E "Fail|Skip|Timeout|Crash" "$OUT/conform_against.log" | cut -c1-240
fi
timeout 300 "$S" conform --cases default --backends vulkan,gl-egl,gles,cpu --require vulkan,gl-egl \
  --json "$OUT/conform.json" > "$OUT/conform.log" 2>&1
echo "live: exit $?; $(grep -c ' max_ulp=0 ' "$OUT/conform.log") comparisons at 0 ulp"
grep -E "Fail|Skip|Timeout|Crash" "$OUT/conform.log" | cut -c1-240
fi

if want bench; then
step "bench (the first process with an empty driver cache)"
__GL_SHADER_DISK_CACHE_PATH=$(emptyCache) timeout 200 "$S" bench "$T" -l "$L" "${A[@]}" --backends vulkan,gl --repeat 20 \
  --json > "$OUT/bench_first.json" 2> "$W/err" || tail -3 "$W/err"
for m in fast strict; do
  flag=(); [ $m = strict ] && flag=(--strict)
  timeout 200 "$S" bench "$T" -l "$L" "${A[@]}" --backends vulkan,gl,cpu --repeat 50 "${flag[@]}" --json > "$OUT/bench_$m.json" 2> "$W/err" || tail -3 "$W/err"
done
medians "$OUT"/bench_first.json "$OUT"/bench_fast.json "$OUT"/bench_strict.json
fi

want whole && {
step "whole deform --binary of the teapot, five runs per backend (ms)"
for b in cpu vulkan gl; do
  ms=()
  for i in 1 2 3 4 5; do
    a=$(date +%s%N)
    "$S" deform "$T" -l "$L" "${A[@]}" --backend $b -o "$W/w.ply" --binary --stats "$OUT/whole_$b.json" --quiet || echo "deform $b: exit $?"
    ms+=($(( ($(date +%s%N) - a) / 1000000 )))
  done
  echo "$b: ${ms[*]}; host phases of the last: $(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['host_ms'])" "$OUT/whole_$b.json")"
done
}

want strict && {
step "strict outputs against the CPU's"
for method in smooth accurate; do
  for p in float double; do
    for b in cpu vulkan gl gles; do
      [ $b = gles ] && [ $p = double ] && continue
      timeout 400 "$S" deform "$T" -l "$L" "${A[@]}" --method $method --strict --precision $p --backend $b \
        -o "$W/$method-$p-$b.ply" --binary --quiet || echo "$method $p $b: exit $?"
    done
    for b in vulkan gl gles; do
      [ -f "$W/$method-$p-$b.ply" ] || continue
      if cmp -s "$W/$method-$p-cpu.ply" "$W/$method-$p-$b.ply"; then echo "$method $p $b: the CPU's bytes"
      else echo "$method $p $b: DIFFERS ($(cmp -l "$W/$method-$p-cpu.ply" "$W/$method-$p-$b.ply" | wc -l) bytes)"; fi
    done
  done
done | tee "$OUT/strict_files.txt"
}

want big && {
step "1,000,000 triangles at level 3: smooth, knot-box clipping, accurate"
python3 tools/make_big_mesh.py --triangles 1000000 "$W/big.ply" > /dev/null
"$S" lattice "$W/big.ply" -o "$W/big.json" --preset twist:0.3 --quiet
# Smooth with either clipping and accurate, each streamed chunk by chunk into the file.
for mode in smooth knot-box accurate; do
  case $mode in smooth) args=;; knot-box) args="--clip knot-box";; accurate) args="--method accurate";; esac
  for b in cpu vulkan gl; do
    python3 - "$mode $b" "$S" deform "$W/big.ply" -l "$W/big.json" --tess 3 --backend $b -o "$W/big-$b.ply" --binary \
      $args --stats "$OUT/big_${mode}_$b.json" --quiet <<'PY'
import resource, subprocess, sys, time
a = time.time(); rc = subprocess.run(sys.argv[2:], timeout=300).returncode
print("%s: exit %d, wall %.1f s, peak RSS %.0f MiB" % (sys.argv[1], rc, time.time() - a,
      resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024))
PY
  done
done | tee "$OUT/big.txt"
rm -f "$W"/big*
}

if [ -n "${TESTS:-}" ] && want tests; then
  step "gtest binaries of $TESTS"
  for t in "$TESTS"/sffd_*_tests; do
    n=$(basename "$t")
    [ "$n" = sffd_core_tests ] && continue   # no device in it
    [ "$n" = sffd_view_tests ] && [ -z "${DISPLAY:-}" ] && continue
    (cd "$(dirname "$t")" && timeout "${TEST_TIMEOUT:-400}" "$t" > "$OUT/$n.log" 2>&1; echo "exit $?" >> "$OUT/$n.log") &
  done
  wait
  for f in "$OUT"/sffd_*_tests.log; do
    echo "$(basename "$f" .log): $(grep -c '^\[       OK \]' "$f") passed, $(grep -E '^\[  FAILED  \] [A-Z]' "$f" | sed 's/ (.*//' | sort -u | wc -l) failed, $(grep -E '^\[  SKIPPED \] [A-Z]' "$f" | sed 's/ (.*//' | sort -u | wc -l) skipped, $(tail -1 "$f")"
    grep -E '^\[  FAILED  \] [A-Z]' "$f" | sort -u
  done
fi
step done
