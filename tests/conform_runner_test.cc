// sffd conform as a conformance runner (docs/CONFORMANCE.md): every kernel's buffers per method, the
// options honoured, skips, crashes and hangs as results, JUnit and JSON, baselines, dumps.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_runner.h"

namespace {

using namespace sffd::test;
using json = nlohmann::json;

const std::string kData = SFFD_TEST_DATA;
const std::string kCube2 = kData + "/cube2.obj -l " + kData + "/lattices/cube2_twist.npy";

// The backends the backend tests run on that a test may use here (usable: a required one missing fails).
std::vector<std::string> backendsHere() {
  std::vector<std::string> names;
  for (const std::string& n : sffd::testing::testBackends())
    if (usable(n)) names.push_back(n);
  return names;
}

bool has(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

// The mismatched count of `buffer`'s line for a pair: "-1" when there is no such line.
std::string totalOf(const std::string& out, const std::string& buffer, const std::string& pair) {
  std::smatch m;
  std::regex re("(^|\\n)" + std::regex_replace(buffer, std::regex("\\."), "\\.") + " " + pair +
                ": max_abs=\\S+ max_ulp=\\d+ mismatched=\\d+/(\\d+)");
  return std::regex_search(out, m, re) ? m[2].str() : "-1";
}

void expectStrictPassEverywhere(const std::string& args, const std::vector<std::string>& buffers) {
  const std::vector<std::string> here = backendsHere();
  if (std::count(here.begin(), here.end(), "vulkan") + std::count(here.begin(), here.end(), "gl-egl") < 2)
    GTEST_SKIP() << "compares vulkan with gl-egl; this machine lacks one";
  std::string backends;
  for (const std::string& n : here) backends += (backends.empty() ? "" : ",") + n;
  RunResult r = runSffd("conform " + args + " --strict --tess 3 --backends " + backends + " --require " + backends);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "\nconform: PASS\n")) << r.out;
  for (const std::string& b : buffers) {
    EXPECT_NE(totalOf(r.out, b, "vulkan vs cpu"), "-1") << b << "\n" << r.out;
    EXPECT_TRUE(has(r.out, b + " vulkan vs gl-egl: max_abs=0 max_ulp=0 mismatched=0/")) << b << "\n" << r.out;
  }
  EXPECT_FALSE(has(r.out, "max_ulp=1")) << r.out;
}

TEST(ConformRunner, StrictSmoothComparesEveryStageOnEveryBackend) {
  expectStrictPassEverywhere(kCube2 + " --method smooth --edge-length 0.5",
                             {"pn.records", "clip.headers", "clip.records", "deform.patches", "deform.tess.positions",
                              "deform.tess.normals"});
}

TEST(ConformRunner, StrictAccurateComparesPatchesAndTessellation) {
  expectStrictPassEverywhere(kCube2 + " --method accurate",
                             {"accurate.patches", "accurate.tess.positions", "accurate.tess.normals"});
}

TEST(ConformRunner, OptionsChangeWhatIsCompared) {
  const std::string base = "conform " + kCube2 + " --strict --backends vulkan,cpu --edge-length 0.5";
  RunResult t3 = runSffd(base + " --tess 3"), t5 = runSffd(base + " --tess 5"), classic = runSffd(base + " --method classic");
  RunResult knot = runSffd(base + " --tess 3 --clip knot-box"), split = runSffd(base + " --tess 3 --split --samples 6");
  for (const RunResult* r : {&t3, &t5, &classic, &knot, &split}) ASSERT_EQ(r->status, 0) << r->out << r->err;
  const std::string pair = "vulkan vs cpu";
  EXPECT_NE(totalOf(t3.out, "deform.tess.positions", pair), totalOf(t5.out, "deform.tess.positions", pair));
  EXPECT_EQ(totalOf(t3.out, "deform.patches", pair), totalOf(t5.out, "deform.patches", pair));
  EXPECT_NE(totalOf(t3.out, "clip.records", pair), totalOf(knot.out, "clip.records", pair));
  EXPECT_EQ(totalOf(t3.out, "deform.tess.positions", pair), totalOf(split.out, "deform.tess.positions", pair));
  EXPECT_NE(totalOf(classic.out, "classic.positions", pair), "-1");
  EXPECT_FALSE(has(classic.out, "pn.records")) << classic.out;
  EXPECT_FALSE(has(classic.out, "deform.")) << classic.out;
}

TEST(ConformRunner, BackendWithoutADisplayIsSkippedUnlessRequired) {
  const std::string args = "conform " + kCube2 + " --method classic --backends vulkan,gl-glfw,cpu";
  RunResult r = runSffd(args, "env -u DISPLAY -u WAYLAND_DISPLAY");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "classic.positions vulkan vs cpu: max_abs=")) << r.out;
  EXPECT_TRUE(has(r.out, "conform: PASS")) << r.out;
  EXPECT_TRUE(has(r.err, "gl-glfw: Skip")) << r.err;
  r = runSffd(args + " --require gl-glfw", "env -u DISPLAY -u WAYLAND_DISPLAY");
  EXPECT_EQ(r.status, 3) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "required backend gl-glfw")) << r.err;
}

TEST(ConformRunner, JunitIsWellFormedAndJsonHasTheFields) {
  fs::path dir = tempDir("conform_reports");
  const fs::path cache = dir / "shader cache";
  RunResult r = runSffd("conform " + kCube2 + " --method accurate --tess 2 --backends vulkan,gl-egl,cpu --junit " +
                            (dir / "r.xml").string() + " --json " + (dir / "r.json").string(),
                        "SFFD_SHADER_CACHE_DIR='" + cache.string() + "'");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  // 3 buffers x 3 pairs; parsed by Python's XML parser as a CI would.
  const std::string check = "python3 -c \"import sys, xml.etree.ElementTree as E; r = E.parse(sys.argv[1]).getroot(); "
                            "c = r.findall('testsuite/testcase'); assert r.tag == 'testsuites' and len(c) == 9, len(c); "
                            "assert all(t.get('classname') and t.get('name') for t in c)\" " + (dir / "r.xml").string();
  EXPECT_EQ(std::system(check.c_str()), 0) << slurp(dir / "r.xml");
  json j = json::parse(slurp(dir / "r.json"));
  EXPECT_EQ(j["status"], "PASS");
  ASSERT_EQ(j["backends"].size(), 3u);
  for (const char* k : {"backend", "device", "driver", "driver_version", "vendor_id", "device_id", "uuid", "shader_cache"})
    EXPECT_TRUE(j["backends"][0].contains(k)) << k;
  EXPECT_EQ(j["backends"][0]["driver_version"].is_string(), true) << j["backends"][0];
  // The shader cache names the folder where Vulkan's kernels came from it (lavapipe 25), else null.
  for (const json& b : j["backends"])
    if (b["backend"] != "vulkan" || !b["shader_cache"].is_string())
      EXPECT_TRUE(b["shader_cache"].is_null()) << b;
    else
      EXPECT_EQ(b["shader_cache"], cache.string()) << b;
  ASSERT_EQ(j["results"].size(), 9u);
  for (const char* k : {"case", "buffer", "pair", "status", "max_abs", "max_ulp", "mismatched", "total", "tolerance",
                        "first_mismatch"})
    EXPECT_TRUE(j["results"][0].contains(k)) << k;
  EXPECT_EQ(j["results"][0]["status"], "Pass");
  fs::remove_all(dir);
}

TEST(ConformRunner, ChangedDumpFailsNamingTheFirstMismatchingElement) {
  fs::path dir = tempDir("conform_dump");
  const std::string args = "conform " + kCube2 + " --strict --tess 3 --edge-length 0.5";
  RunResult r = runSffd(args + " --backends vulkan,cpu --dump " + (dir / "d").string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  json manifest = json::parse(slurp(dir / "d/manifest.json"));
  EXPECT_TRUE(manifest["cases"][0]["input_hashes"].contains("mesh"));
  EXPECT_EQ(manifest["cases"][0]["variant"], "strict float");
  r = runSffd(args + " --backends cpu,vulkan --against " + (dir / "d").string());
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(runSffd(args + " --split --backends cpu --against " + (dir / "d").string()).status, 2);   // other options
  EXPECT_TRUE(has(r.out, "deform.tess.positions dump:cpu vs cpu: max_abs=0 max_ulp=0 mismatched=0/")) << r.out;
  EXPECT_TRUE(has(r.out, "deform.tess.positions dump:vulkan vs vulkan: max_abs=0 max_ulp=0")) << r.out;
  // One value changed: at level 3 a sub-triangle has 10 vertices (40 values), so element 85 is sub-triangle 2, value 1 (y).
  const size_t element = 4 * 10 * 2 + 5;
  {
    std::fstream f(dir / "d/cpu/cube2/deform.tess.positions.f64", std::ios::in | std::ios::out | std::ios::binary);
    double v = 0;
    f.seekg(std::streamoff(element * 8));
    f.read(reinterpret_cast<char*>(&v), 8);
    v += 0.25;
    f.seekp(std::streamoff(element * 8));
    f.write(reinterpret_cast<const char*>(&v), 8);
  }
  r = runSffd(args + " --backends cpu --against " + (dir / "d").string() + " --json " + (dir / "r.json").string());
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "deform.tess.positions dump:cpu vs cpu: max_abs=0.25 max_ulp=")) << r.out;
  EXPECT_TRUE(has(r.out, "mismatched=1/")) << r.out;
  EXPECT_TRUE(has(r.err, "first mismatch deform.tess.positions[" + std::to_string(element) +
                             "]: sub-triangle 2 (input triangle ")) << r.err;
  EXPECT_TRUE(has(r.out, "conform: FAIL")) << r.out;
  json j = json::parse(slurp(dir / "r.json"));
  bool found = false;
  for (const json& res : j["results"])
    if (res["buffer"] == "deform.tess.positions") {
      found = true;
      EXPECT_EQ(res["status"], "Fail");
      EXPECT_EQ(res["first_mismatch"]["element"], element);
    }
  EXPECT_TRUE(found);
  // A damaged dump is one input error line naming its file: a count past what the file holds was allocated
  // ("out of memory", exit 1), a broken index was nlohmann's message (exit 1).
  const fs::path index = dir / "d/cpu/cube2/buffers.json";
  json idx = json::parse(slurp(index));
  idx["buffers"][0]["count"] = uint64_t(1) << 50;
  std::ofstream(index) << idx.dump();
  r = runSffd(args + " --backends cpu --against " + (dir / "d").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err, "sffd: error: " + (dir / "d/cpu/cube2" / idx["buffers"][0]["file"].get<std::string>()).string() +
                       ": shorter than its buffers.json says\n");
  std::ofstream(index) << "{";
  r = runSffd(args + " --backends cpu --against " + (dir / "d").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("sffd: error: " + index.string() + ": not a --dump buffer index: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  fs::remove_all(dir);
}

// Two cases, so a crash or a hang in the first shows that the run goes on with the second.
fs::path twoCases(const fs::path& dir) {
  std::ofstream(dir / "two.cases") << "first " << kData << "/cube2.obj -l " << kData
                                   << "/lattices/cube2_twist.npy --method classic --strict\n"
                                   << "second " << kData << "/cube.obj -l " << kData
                                   << "/lattices/cube_bend.npy --method classic --strict\n";
  return dir / "two.cases";
}

TEST(ConformRunner, InjectedCrashHangAndLongCompileAreResultsAndTheRunGoesOn) {
  fs::path dir = tempDir("conform_faults");
  const std::string args = "conform --cases " + twoCases(dir).string() + " --backends vulkan,cpu --timeout 2 --json " +
                           (dir / "r.json").string();
  RunResult r = runSffd(args, "SFFD_CONFORM_FAULT=crash:vulkan:first");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  // SIGSEGV (11), or SIGABRT (6) where a sanitizer catches the segfault and aborts.
  EXPECT_TRUE(has(r.err, "vulkan first: Crash: killed by signal 11") || has(r.err, "vulkan first: Crash: killed by signal 6"))
      << r.err;
  EXPECT_TRUE(has(r.out, "second/classic.positions vulkan vs cpu: max_abs=0 max_ulp=0 mismatched=0/")) << r.out;
  json j = json::parse(slurp(dir / "r.json"));
  EXPECT_EQ(j["results"][0]["test"], "first/classic.positions/vulkan-vs-cpu");
  EXPECT_EQ(j["results"][0]["status"], "Crash");

  r = runSffd(args, "SFFD_CONFORM_FAULT=hang:vulkan:first");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "vulkan first: Timeout: no progress for 2 s")) << r.err;
  EXPECT_TRUE(has(r.out, "second/classic.normals vulkan vs cpu: max_abs=0")) << r.out;

  // A kernel compile longer than --timeout is progress (NVIDIA's GL compiles the strict double clip_write
  // for 75 s): the child says so while it lasts ...
  r = runSffd(args, "SFFD_CONFORM_FAULT=slow-compile:cpu:first");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "first/classic.positions vulkan vs cpu: max_abs=0 max_ulp=0 mismatched=0/")) << r.out;
  // So is a device's opening that lasts longer than --timeout (a disk busy writing back, a GPU driver's first start).
  r = runSffd(args, "SFFD_CONFORM_FAULT=slow-open:vulkan");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "second/classic.positions vulkan vs cpu: max_abs=0 max_ulp=0 mismatched=0/")) << r.out;
  // ... for at most ten timeouts.
  r = runSffd(args, "SFFD_CONFORM_FAULT=stuck-compile:cpu:first");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "cpu first: Timeout: a kernel compile ran past 20 s (10 times --timeout)")) << r.err;
  EXPECT_TRUE(has(r.out, "second/classic.normals vulkan vs cpu: max_abs=0")) << r.out;
  // A hang after a compile has ended is no progress, reported after --timeout, not after ten.
  r = runSffd(args, "SFFD_CONFORM_FAULT=compile-then-hang:cpu:first");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "cpu first: Timeout: no progress for 2 s")) << r.err;
  EXPECT_TRUE(has(r.out, "second/classic.normals vulkan vs cpu: max_abs=0")) << r.out;

  // The crash listed in a baseline is an expected failure (exit 0); a listed test that passes is not.
  std::ofstream(dir / "failures.csv") << "# test,status\nfirst/classic.positions/vulkan-vs-cpu,Crash\n"
                                      << "first/classic.normals/vulkan-vs-cpu,Crash\n";
  r = runSffd(args + " --baseline " + (dir / "failures.csv").string(), "SFFD_CONFORM_FAULT=crash:vulkan:first");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "conform: PASS")) << r.out;
  r = runSffd(args + " --baseline " + (dir / "failures.csv").string());
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "UnexpectedPass first/classic.normals/vulkan-vs-cpu")) << r.err;
  fs::remove_all(dir);
}

TEST(ConformRunner, DefaultCasesCoverEveryKernel) {
  RunResult r = runSffd("conform --cases default --backends vulkan,cpu");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  for (const char* b : {"classic.positions", "classic.normals", "pn.records", "clip.headers", "clip.records",
                        "deform.patches", "deform.tess.positions", "deform.tess.normals", "accurate.patches",
                        "accurate.tess.positions", "accurate.tess.normals"})
    EXPECT_TRUE(has(r.out, std::string("/") + b + " vulkan vs cpu: ")) << b;
  for (const char* c : {"smooth-cube-split/", "smooth-cube2-knot-box/", "classic-sphere-double/", "accurate-cube-fast/"})
    EXPECT_TRUE(has(r.out, c)) << c;
}

TEST(ConformRunner, BadUsageIsExit2) {
  EXPECT_EQ(runSffd("conform").status, 2);
  EXPECT_EQ(runSffd("conform " + kCube2 + " --backends vulkan,metal").status, 2);
  EXPECT_EQ(runSffd("conform " + kCube2 + " --method nope").status, 2);
  EXPECT_EQ(runSffd("conform " + kCube2 + " --cases default").status, 2);
  EXPECT_EQ(runSffd("conform " + kCube2 + " --timeout 0").status, 2);
  EXPECT_EQ(runSffd("conform " + kCube2 + " --backends cpu,vulkan --require gl-egl").status, 2);
}

// What conform writes and reads besides the job is checked before the run: the result files never
// overwrite an input (they did: --junit MESH, --json LATTICE), a --dump that cannot be made and a damaged
// --against manifest are one input error line (they were std::filesystem's and nlohmann's, exit 1, the
// latter after every backend had run); and a huge --timeout waits (it was a Timeout at once).
TEST(ConformRunner, ResultFilesAndFoldersAreCheckedBeforeTheRun) {
  const fs::path dir = tempDir("conform_paths");
  fs::copy_file(kData + "/cube2.obj", dir / "m.obj");
  fs::copy_file(kData + "/lattices/cube2_twist.npy", dir / "l.npy");
  std::ofstream(dir / "my.cases") << "c m.obj -l l.npy --tess 2\n";
  std::ofstream(dir / "base.csv") << "c/pn.records cpu vs cpu,Fail\n";
  std::ofstream(dir / "empty");
  fs::create_directories(dir / "bad");
  std::ofstream(dir / "bad" / "manifest.json") << "{\"cases\": 3}\n";
  const std::string m = (dir / "m.obj").string(), l = (dir / "l.npy").string(), cases = (dir / "my.cases").string(),
                    base = (dir / "base.csv").string();
  const std::string before[] = {slurp(m), slurp(l), slurp(cases), slurp(base)};
  const std::string job = "conform " + m + " -l " + l + " --backends cpu,cpu --tess 2 --quiet";
  const std::pair<std::string, std::string> refused[] = {
      {job + " --junit " + m, m + ": output path is an input file"},
      {job + " --json " + l, l + ": output path is an input file"},
      {"conform --cases " + cases + " --backends cpu,cpu --quiet --json " + cases, cases + ": output path is an input file"},
      {job + " --baseline " + base + " --junit " + base, base + ": output path is an input file"},
      {job + " --dump " + (dir / "empty").string(), (dir / "empty").string() + ": cannot make the dump folder"},
      {job + " --against " + (dir / "bad").string() + " --dump " + (dir / "d").string(),
       (dir / "bad" / "manifest.json").string() + ": not a --dump manifest"},
  };
  for (const auto& [args, message] : refused) {
    RunResult r = runSffd(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("sffd: error: " + message, 0), 0u) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_EQ(r.out, "") << args;   // refused before any backend ran
  }
  EXPECT_EQ(slurp(m), before[0]);
  EXPECT_EQ(slurp(l), before[1]);
  EXPECT_EQ(slurp(cases), before[2]);
  EXPECT_EQ(slurp(base), before[3]);
  EXPECT_FALSE(fs::exists(dir / "d"));
  // A --json that cannot be written after the --junit was: neither is left.
  RunResult j = runSffd(job + " --junit " + (dir / "j.xml").string() + " --json /proc/sffd-conform.json");
  EXPECT_EQ(j.status, 2) << j.err;
  EXPECT_EQ(j.err, "sffd: error: /proc/sffd-conform.json: cannot write: No such file or directory\n");
  EXPECT_FALSE(fs::exists(dir / "j.xml"));
  // A --junit file it replaced is put back (it was taken away), and nothing else is left beside it.
  fs::create_directories(dir / "out");
  std::ofstream(dir / "out" / "k.xml") << "the user's report";
  j = runSffd(job + " --junit " + (dir / "out" / "k.xml").string() + " --json /proc/sffd-conform.json");
  EXPECT_EQ(j.status, 2) << j.err;
  EXPECT_EQ(slurp(dir / "out" / "k.xml"), "the user's report");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "out"), fs::directory_iterator()), 1);
  // A device, a pipe or the file stdout goes to is written in place (/dev/stdout works); a write that fails is
  // an error (into /dev/full the report was lost with exit status 0).
  RunResult full = runSffd(job + " --json /dev/full");
  EXPECT_EQ(full.status, 2) << full.err;
  EXPECT_EQ(full.err, "sffd: error: /dev/full: cannot write: write failed (disk full?)\n");
  RunResult out = runSffd(job + " --json /dev/stdout");
  EXPECT_EQ(out.status, 0) << out.err;
  EXPECT_TRUE(has(out.out, "\"format\": \"sffd-conform-results\"")) << out.out;
  RunResult r = runSffd(job + " --timeout 1e300");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "conform: PASS")) << r.out;
  fs::remove_all(dir);
}

// Each backend writes a case's buffers to the folder named after the case: "." and ".." were accepted, and
// ".." put every backend's buffers in one folder, so each backend was compared with the last one run: a
// PASS whatever they computed. Refused in a case file; a mesh whose stem is one ("...obj") names its case "mesh".
TEST(ConformRunner, CaseNamesAreFolderNames) {
  const fs::path dir = tempDir("conform_case_names");
  fs::copy_file(kData + "/cube2.obj", dir / "...obj");
  fs::copy_file(kData + "/lattices/cube2_twist.npy", dir / "l.npy");
  for (const char* name : {".", ".."}) {
    std::ofstream(dir / "dot.cases") << name << " ...obj -l l.npy --tess 2\n";
    RunResult r = runSffd("conform --cases " + (dir / "dot.cases").string() + " --backends cpu,cpu --quiet");
    EXPECT_EQ(r.status, 2) << name << "\n" << r.err;
    EXPECT_TRUE(has(r.err, "dot.cases:1: a case name has no / , \" < > & or spaces and is not . or ..")) << r.err;
  }
  RunResult r = runSffd("conform " + (dir / "...obj").string() + " -l " + (dir / "l.npy").string() +
                        " --backends cpu,cpu --tess 2 --quiet --json " + (dir / "r.json").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json::parse(slurp(dir / "r.json"))["cases"][0]["name"], "mesh");
  fs::remove_all(dir);
}

TEST(ConformRunner, DevicesJsonHasIdsAndDriverVersion) {
  RunResult r = runSffd("devices --json");
  ASSERT_EQ(r.status, 0) << r.err;
  json j = json::parse(r.out);
  ASSERT_FALSE(j["devices"].empty());
  bool vulkan = false;
  for (const json& d : j["devices"]) {
    for (const char* k : {"backend", "device", "driver", "driver_version", "vendor_id", "device_id", "uuid"})
      EXPECT_TRUE(d.contains(k)) << k;
    if (d["backend"] == "vulkan") {
      vulkan = true;
      EXPECT_TRUE(d["vendor_id"].is_number()) << d;
      EXPECT_EQ(d["uuid"].get<std::string>().size(), 32u) << d;
    }
  }
  EXPECT_TRUE(vulkan) << r.out;
}

}  // namespace
