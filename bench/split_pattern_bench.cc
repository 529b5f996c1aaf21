// The crack-free split-pattern table (kernels/clip/split_pattern_table.h, docs/SPLIT_PATTERNS.md): the
// cost of generating it and of reading it. The generator (tools/split_pattern_gen.cpp) runs on every
// clean build and its cost grows roughly as Nmax^5 (Nmax^3 patterns, each a Delaunay + Lloyd
// triangulation of up to ~Nmax^2 points), which bounds how far SFFD_SPLIT_NMAX can be raised. Its core
// lives in an anonymous namespace next to its main(), not in a callable library function, so the
// benchmark runs the built tool executable (split_pattern_gen, path baked in at configure time) via
// std::system with a temporary output file, one iteration per Nmax, timed by hand
// (UseManualTime/SetIterationTime; it includes process start-up and writing the generated source,
// a few ms). The lookup benchmarks measure splitPatternTable().pattern(a, b, c), which the CPU
// regular clipping calls once per clip triangle, and a full walk over a pattern's vertices and
// triangles as the clip kernel does.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

#include "kernels/clip/split_pattern_table.h"

using namespace sffd;
namespace fs = std::filesystem;

namespace {

// Sorted valid triples a <= b <= c <= min(nmax, a + b): the patterns of a table.
int64_t patternCount(int nmax) {
  int64_t n = 0;
  for (int a = 1; a <= nmax; ++a)
    for (int b = a; b <= nmax; ++b) n += std::min(nmax, a + b) - b + 1;
  return n;
}

// Arg: Nmax. One run of the generator tool per iteration. Items = patterns generated.
void BM_SplitPatternGenerate(benchmark::State& state) {
  const int nmax = int(state.range(0));
  const fs::path out = fs::temp_directory_path() /
                       ("sffd_bench_split_patterns_" + std::to_string(getpid()) + "_" + std::to_string(nmax) + ".cpp");
  const std::string cmd = std::string("\"") + SFFD_SPLIT_PATTERN_GEN + "\" --nmax " + std::to_string(nmax) + " \"" +
                          out.string() + "\"";
  std::error_code ec;
  for (auto _ : state) {
    fs::remove(out, ec);   // the tool skips the write when the file is already up to date
    auto start = std::chrono::steady_clock::now();
    int rc = std::system(cmd.c_str());
    auto stop = std::chrono::steady_clock::now();
    if (rc != 0) {
      state.SkipWithError(("split_pattern_gen failed: " + cmd).c_str());
      break;
    }
    state.SetIterationTime(std::chrono::duration<double>(stop - start).count());
  }
  state.counters["source_MB"] = double(fs::file_size(out, ec)) / 1e6;
  fs::remove(out, ec);
  state.SetItemsProcessed(int64_t(state.iterations()) * patternCount(nmax));
}
BENCHMARK(BM_SplitPatternGenerate)
    ->ArgName("nmax")
    ->Arg(8)
    ->Arg(16)
    ->Arg(24)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// Every valid sorted triple of the compiled table looked up once. Items = lookups.
void BM_SplitPatternLookup(benchmark::State& state) {
  const SplitPatternTable& T = splitPatternTable();
  const int nmax = T.nmax();
  for (auto _ : state) {
    uint64_t sum = 0;
    for (int a = 1; a <= nmax; ++a)
      for (int b = a; b <= nmax; ++b)
        for (int c = b; c <= std::min(nmax, a + b); ++c) sum += T.pattern(a, b, c).triangleCount;
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * patternCount(nmax));
  state.counters["nmax"] = nmax;
}
BENCHMARK(BM_SplitPatternLookup)->Unit(benchmark::kMicrosecond);

// Lookup plus a read of every vertex and triangle index of the pattern (what one clip triangle
// costs in table traffic). Items = sub-triangles read.
void BM_SplitPatternWalk(benchmark::State& state) {
  const SplitPatternTable& T = splitPatternTable();
  const int nmax = T.nmax();
  int64_t triangles = 0;
  for (auto _ : state) {
    float acc = 0;
    triangles = 0;
    for (int a = 1; a <= nmax; ++a)
      for (int b = a; b <= nmax; ++b)
        for (int c = b; c <= std::min(nmax, a + b); ++c) {
          const SplitPattern& p = T.pattern(a, b, c);
          for (const SplitPatternVertex& v : T.vertices(p)) acc += v.lambda[0];
          for (uint16_t i : T.triangles(p)) acc += float(i);
          triangles += p.triangleCount;
        }
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * triangles);
  state.counters["table_tris"] = double(triangles);
}
BENCHMARK(BM_SplitPatternWalk)->Unit(benchmark::kMillisecond);

}  // namespace
