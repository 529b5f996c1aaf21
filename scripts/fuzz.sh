#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ (clang, ASan + UBSan) in build-fuzz/ and runs each for SECONDS
# (default 60) from a seed corpus: the test data of tests/data/ (models and lattices, PyGeM's fixtures), the
# demo's data/, tests/data/bad/ (the bad-input corpus, the odd
# inputs and the fuzzers' own regression files under tests/data/bad/fuzz/TARGET/).
#   scripts/fuzz.sh [SECONDS]
# Every seed is run first, so the regression files are re-checked by each run. New inputs that reach
# new code are kept in build-fuzz/corpus/TARGET/ for the next run. Exit status 0: no crash, hang or
# leak; 1: some target failed, its input is in build-fuzz/crashes/TARGET/ (turn it into a regression
# file under tests/data/bad/fuzz/, docs/ROBUSTNESS.md says how).
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-60}
[[ "$secs" =~ ^[0-9]+$ ]] || { echo "usage: scripts/fuzz.sh [SECONDS]" >&2; exit 2; }
scripts/deps.sh

build=build-fuzz
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSFFD_FUZZ=ON \
  -DSFFD_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" -j2 --target sffd_fuzz

# Seeds per target, by extension.
declare -A exts=(
  [fuzz_mesh_text]="obj off bpt ply stl"
  [fuzz_mesh_binary]="ply stl om glb gltf"
  [fuzz_lattice]="json prm npy"
)
declare -A dicts=([fuzz_mesh_text]=fuzz/mesh.dict [fuzz_mesh_binary]=fuzz/mesh.dict [fuzz_lattice]=fuzz/lattice.dict)

export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
status=0
passed=0
failed=0
summary=()
for t in fuzz_mesh_text fuzz_mesh_binary fuzz_lattice; do
  seeds="$build/seeds/$t" corpus="$build/corpus/$t" crashes="$build/crashes/$t"
  rm -rf "$seeds"
  mkdir -p "$seeds" "$corpus" "$crashes"
  for e in ${exts[$t]}; do
    find tests/data data -type f -name "*.$e" -size -1024k -exec cp -t "$seeds" --backup=numbered {} + 2>/dev/null || true
  done
  [ -d "tests/data/bad/fuzz/$t" ] && cp -t "$seeds" --backup=numbered tests/data/bad/fuzz/"$t"/* 2>/dev/null || true
  log="$build/$t.log"
  echo "fuzz: $t for ${secs}s from $(ls "$seeds" | wc -l) seeds" >&2
  set +e
  "$build/fuzz/$t" "$corpus" "$seeds" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
    -dict="${dicts[$t]}" -artifact_prefix="$crashes/" -print_final_stats=1 >"$log" 2>&1
  rc=$?
  set -e
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo 0)
  if [ $rc -ne 0 ]; then
    status=1
    echo "fuzz: $t FAILED (exit $rc); the input is in $crashes/:" >&2
    grep -E 'ERROR|SUMMARY|Test unit written|fuzz invariant' "$log" | head -20 >&2 || tail -30 "$log" >&2
    summary+=("$t: FAILED after ${runs:-?} runs ($log)")
    failed=$((failed + 1))
  else
    summary+=("$t: ${runs} runs in ${secs}s, ${cov} coverage points, $(ls "$corpus" | wc -l) corpus files, no crash")
    passed=$((passed + 1))
  fi
done
printf 'fuzz: %s\n' "${summary[@]}" >&2
echo "fuzz: $passed passed, $failed failed"
exit $status
