// sffd bench MESH -l LATTICE: per-stage times of smooth FFD (the paper's Tables 1 and 2) on each
// backend asked, through sffd::Deformer (on a GPU the device-resident DeformSession, the path `view` uses): the
// pre-compute (PN + clip) and the deform stage are timed apart, from GPU timestamps (Vulkan
// timestamp queries, GL timestamp pairs) with the host wall time beside them; the first,
// cold run (kernel compilation) is reported apart; then --warmup runs, then --repeat timed runs.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include <sffd/deformer.h>
#include <sffd/error.h>

#include "apps/sffd/cli.h"
#include "apps/sffd/deform_job.h"
#include "core/job_budget.h"
#include "core/shader_binary_cache.h"
#include "core/wall_clock.h"
#include "kernels/smooth/smooth_deform.h"
#include "pipelines/deformer_internal.h"

namespace sffd::cli {
namespace {

double peakRssMb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;   // KiB on Linux
}

// Samples of one named quantity over the timed runs.
struct Series {
  std::map<std::string, std::vector<double>> values;
  std::vector<std::string> order;   // first-seen order, for the output
  void add(const std::string& key, double ms) {
    if (!values.count(key)) order.push_back(key);
    values[key].push_back(ms);
  }
};

nlohmann::ordered_json summary(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  double median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  return {{"median", median}, {"min", v.front()}, {"max", v.back()}};
}

struct BenchSettings {
  DeformOptions options;
  int warmup = 2, repeat = 20;
};

struct BackendResult {
  std::string label, device, driver;   // driver: the version string, so figures name the Mesa generation
  double coldMs = 0;          // first pre-compute + deform, compilation included
  Series stages, host;        // GPU (or CPU) stage times; host wall times
  size_t subTriangles = 0;
  double peakRss = 0;
  ShaderBinaryCache::Counts shaderCache;   // during this backend's runs (docs/CLI.md "Shader cache")
};

void addStages(Series& s, const Timings& pre, const Timings& def) {
  s.add("pn", pre.pnMs);
  s.add("clip", pre.clipMs);
  s.add("deform", def.deformMs);
  s.add("total", pre.pnMs + pre.clipMs + def.deformMs);
  std::map<std::string, double> steps;   // --split: deform.sample, ... in name order
  for (const auto& [label, ms] : def.steps)
    if (label.find('.') != std::string::npos) steps[label] += ms;
  for (const auto& [k, v] : steps) s.add(k, v);
}

// One device: a Deformer made and deformed once (the cold run), then per run the pre-compute again
// (PN triangles, clipping) and a deform; nothing is downloaded.
BackendResult benchDevice(Device& device, const Job& job, const BenchSettings& S) {
  BackendResult r;
  r.label = device.label();
  r.device = device.info().name;
  r.driver = device.info().driver;
  auto t0 = std::chrono::steady_clock::now();
  Deformer deformer(device, job.mesh, job.lattice, S.options);
  deformer.deform(job.lattice);
  r.coldMs = msSince(t0);
  r.subTriangles = deformer.subTriangles();
  for (int i = 0; i < S.warmup + S.repeat; ++i) {
    Timings pre;
    deformer.internal().run->precompute(pre);
    Timings def = deformer.deform(job.lattice);
    if (i < S.warmup) continue;
    addStages(r.stages, pre, def);
    r.host.add("precompute", pre.wallMs);
    r.host.add("deform", def.wallMs);
  }
  r.peakRss = peakRssMb();
  return r;
}

int run(const ParsedArgs& args) {
  args.requireValue("--lattice");
  if (args.get("--method", "smooth") != "smooth")
    throw Error(ErrorKind::Input, "bench measures --method smooth (the stages pn, clip, deform)");
  std::string clipName = args.get("--clip", "regular");
  if (clipName != "regular" && clipName != "knot-box") throw Error(ErrorKind::Input, "--clip must be regular or knot-box");
  BenchSettings S;
  S.repeat = args.getInt("--repeat", 20, 1, 100000);
  S.warmup = args.getInt("--warmup", 2, 0, 100000);
  auto opt = [&](const char* o) { return args.has(o) ? std::optional<std::string>(args.get(o)) : std::nullopt; };
  checkSizeOptions(opt("--edge-length"), opt("--tess"));   // in deform's words
  const std::vector<std::string> names = args.getList("--backends", "vulkan,gl");
  if (names.empty()) throw Error(ErrorKind::Input, "--backends names no backend");
  // Named backends only, checked before any runs (docs/CLI.md): auto would time one of them again under its
  // name, and gl-glfw the GL driver gl-egl times, in a window.
  static constexpr std::string_view known[] = {"vulkan", "gl", "gl-egl", "gl-osmesa", "gles", "cpu"};
  checkBackendNames(names, known);
  Job job = loadJob(args);
  DeformOptions& o = S.options;
  o.strict = args.has("--strict");
  o.tess = args.getInt("--tess", 10);
  o.edgeLength = edgeLengthOf(args, job.mesh);
  checkEdgeLength(job.mesh, o.edgeLength);
  o.samples = samplesOf(args);
  o.clip = clipName == "knot-box" ? Clip::KnotBox : Clip::Regular;
  o.split = args.has("--split");
  o.creaseAngleDeg = creaseAngleOf(args);
  o.maxChunkElements = chunkFromEnvironment("SFFD_MAX_CHUNK_SUBTRIANGLES");
  if (args.get("--precision", "float") == "double") o.precision = Precision::Double;
  else if (args.get("--precision", "float") != "float") throw Error(ErrorKind::Input, "--precision must be float or double");
  else o.precision = Precision::Float;

  std::vector<BackendResult> results;
  for (const std::string& name : names) {
    DeviceRequest req;
    req.name = name;
    if (name != "cpu") req.deviceSubstring = args.get("--device");
    std::vector<std::string> notes;
    const ShaderBinaryCache::Counts before = ShaderBinaryCache::counts();
    Device device = Device::open(req, &notes);
    if (name != "cpu" && device.info().api == "cpu") throw Error(ErrorKind::Device, "backend '" + name + "' gave no GPU device");
    results.push_back(benchDevice(device, job, S));
    const ShaderBinaryCache::Counts after = ShaderBinaryCache::counts();
    results.back().shaderCache = {after.hits - before.hits, after.misses - before.misses, after.stores - before.stores};
  }

  const size_t subs = results.empty() ? 0 : results.front().subTriangles;
  std::string meshName = job.meshPath.substr(job.meshPath.find_last_of('/') + 1);
  if (args.has("--json")) {
    nlohmann::ordered_json j = {{"mesh", meshName},
                                {"method", "smooth"},
                                {"clip", clipName},
                                {"edge_length", o.edgeLength},
                                {"tess", o.tess},
                                {"input_triangles", job.mesh.triangles.size()},
                                {"sub_triangles", subs},
                                {"output_triangles", subs * size_t(tessTriangleCount(o.tess))},
                                {"runs", nlohmann::ordered_json::array()}};
    for (const BackendResult& r : results) {
      nlohmann::ordered_json run = {{"backend", r.label}, {"device", r.device}, {"driver", r.driver},
                                    {"repeat", S.repeat},
                                    {"cold_first_dispatch_ms", r.coldMs}};
      nlohmann::ordered_json stages = nlohmann::ordered_json::object(), host = nlohmann::ordered_json::object();
      for (const std::string& k : r.stages.order) stages[k] = summary(r.stages.values.at(k));
      for (const std::string& k : r.host.order) host[k] = summary(r.host.values.at(k));
      run["stages_ms"] = stages;
      run["host_wall_ms"] = host;
      run["peak_rss_mb"] = r.peakRss;
      run["shader_cache"] = {{"hits", r.shaderCache.hits}, {"misses", r.shaderCache.misses}, {"stores", r.shaderCache.stores}};
      j["runs"].push_back(run);
    }
    std::printf("%s\n", j.dump(1).c_str());
    return 0;
  }
  std::printf("%s: smooth FFD, %zu triangles -> %zu sub-triangles (l = %g, %s clipping) -> %zu output triangles (level %d)\n",
              meshName.c_str(), job.mesh.triangles.size(), subs, o.edgeLength, clipName.c_str(),
              subs * size_t(tessTriangleCount(o.tess)), o.tess);
  std::printf("median of %d runs after %d warm-up, min..max in brackets; GPU timestamps (cpu, gl-osmesa: wall clock)\n", S.repeat, S.warmup);
  for (const BackendResult& r : results) {
    std::printf("%-10s %s, %s\n", r.label.c_str(), r.device.c_str(), r.driver.c_str());
    auto line = [&](const Series& s, const std::string& k) {
      nlohmann::ordered_json m = summary(s.values.at(k));
      std::printf("  %-20s %9.3f ms  [%.3f .. %.3f]\n", k.c_str(), m["median"].get<double>(), m["min"].get<double>(),
                  m["max"].get<double>());
    };
    for (const std::string& k : r.stages.order) line(r.stages, k);
    for (const std::string& k : r.host.order) {
      nlohmann::ordered_json m = summary(r.host.values.at(k));
      std::printf("  host %-15s %9.3f ms  [%.3f .. %.3f]\n", k.c_str(), m["median"].get<double>(), m["min"].get<double>(),
                  m["max"].get<double>());
    }
    std::printf("  cold first run       %9.3f ms   peak RSS %.1f MiB\n", r.coldMs, r.peakRss);
    if (r.shaderCache.hits + r.shaderCache.misses > 0)
      std::printf("  shader cache         %llu kernels from it, %llu from SPIR-V\n", (unsigned long long)r.shaderCache.hits,
                  (unsigned long long)r.shaderCache.misses);
  }
  return 0;
}

}  // namespace

CommandSpec benchCommand() {
  std::vector<OptionSpec> options;
  for (const OptionSpec& o : jobOptions()) {
    std::string n = o.name;
    if (n == "--backend" || n == "--stats" || n == "--method" || n.rfind("--precision", 0) == 0) continue;
    options.push_back(o);
  }
  options.insert(options.begin() + 1, {"--backends", "LIST", "comma-separated backends to time: vulkan, gl, gl-egl, gl-osmesa, gles, cpu (default vulkan,gl)"});
  options.insert(options.begin() + 2, {"--repeat", "N", "timed runs per backend (default 20); the median, min and max are reported"});
  options.insert(options.begin() + 3, {"--warmup", "N", "untimed runs after the cold first run (default 2)"});
  options.insert(options.begin() + 4, {"--json", nullptr, "print the results as JSON (docs/CLI.md) instead of a table"});
  options.insert(options.begin() + 5, {"--method", "NAME", "smooth (the only method with the pn, clip and deform stages)"});
  options.insert(options.begin() + 6, {"--precision", "NAME", "float (default) or double kernels"});
  return CommandSpec{"bench", "MESH -l LATTICE [--backends LIST] [--repeat N] [--json]",
                     "Times the stages of smooth FFD (pn, clip, deform) on each backend asked.", options, run, 1, 1};
}

}  // namespace sffd::cli
