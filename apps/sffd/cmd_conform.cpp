// sffd conform: runs cases (one from the command line, or a case set) on several backends, each in
// its own child process, and compares every output buffer pairwise or against a dump of another run.
// Exit 0 when nothing failed, 1 on a Fail, Crash, Timeout or UnexpectedPass, 2 for bad usage, 3 when
// a backend named by --require cannot be opened (docs/CONFORMANCE.md).
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>
#include <sffd/error.h>
#include <sffd/sffd.h>

#include "apps/sffd/conform.h"
#include "io/io_util.h"

namespace sffd::cli {
namespace {

using namespace conform;
using json = nlohmann::ordered_json;

// Where `--cases default` finds tests/data/conform/default.cases.
std::string dataDir() {
  if (const char* d = std::getenv("SFFD_CONFORM_DATA"); d && *d) return d;
  return SFFD_SOURCE_DATA;
}

// A case's options without its input paths (those are checked by hash): what a dump must share.
json optionsOf(const Case& c) {
  json args = json::array();
  for (size_t i = 1; i < c.argv.size(); ++i)
    if (c.argv[i] != "--lattice" && c.argv[i] != "-l" && c.argv[i - 1] != "--lattice" && c.argv[i - 1] != "-l")
      args.push_back(c.argv[i]);
  return args;
}

void writeManifest(const fs::path& dir, const std::vector<Case>& cases, const std::vector<BackendRun>& runs) {
  json m{{"format", "sffd-conform-dump"}, {"version", 1},
         {"sffd", sffd::version()}};
  m["backends"] = json::array();
  for (const BackendRun& b : runs) {
    json d = b.opened ? json::parse(deviceJson(b.label, b.info)) : json{{"backend", b.label}};
    d["dir"] = fs::relative(b.dir, dir).string();
    d["opened"] = b.opened;
    d["cases"] = json::object();
    for (size_t i = 0; i < cases.size(); ++i)
      d["cases"][cases[i].name] = {{"status", statusName(b.cases[i].status)}, {"detail", b.cases[i].detail}};
    m["backends"].push_back(d);
  }
  m["cases"] = json::array();
  for (const Case& c : cases) {
    m["cases"].push_back({{"name", c.name}, {"method", c.method()}, {"variant", c.variant()}, {"options", optionsOf(c)},
                          {"input_hashes", inputHashes(c)}});
  }
  std::ofstream(dir / "manifest.json") << m.dump(1) << "\n";
}

// The dumped backends as runs: the same cases (by name), their inputs checked against the dump's hashes.
std::vector<BackendRun> readDump(const fs::path& dir, const std::vector<Case>& cases) try {
  std::ifstream in(dir / "manifest.json");
  if (!in) throw Error(ErrorKind::Input, (dir / "manifest.json").string() + ": cannot read (is it a --dump folder?)");
  json m = json::parse(in);
  std::map<std::string, json> dumped;
  for (const json& c : m.at("cases")) dumped[c.at("name")] = c;
  for (const Case& c : cases) {
    auto it = dumped.find(c.name);
    if (it == dumped.end()) continue;
    if (it->second.at("input_hashes") != json(inputHashes(c)))
      throw Error(ErrorKind::Input, "case " + c.name + ": its mesh or lattice differs from the one dumped in " + dir.string());
    if (it->second.at("options") != optionsOf(c))
      throw Error(ErrorKind::Input, "case " + c.name + ": dumped with the options " + it->second.at("options").dump() +
                                        ", run with " + optionsOf(c).dump());
  }
  std::vector<BackendRun> runs;
  for (const json& b : m.at("backends")) {
    if (!b.value("opened", false)) continue;
    BackendRun r;
    r.label = r.name = "dump:" + b.at("backend").get<std::string>();
    r.opened = true;
    r.info.api = b.value("api", "");
    r.info.name = b.value("device", "");
    r.info.driver = b.value("driver", "");
    if (b["driver_version"].is_string()) r.info.driverVersion = b["driver_version"];
    if (b.contains("shader_cache") && b["shader_cache"].is_string()) r.info.shaderCache = b["shader_cache"];
    r.dir = dir / b.at("dir").get<std::string>();
    for (const Case& c : cases) {
      const json& st = b.at("cases").contains(c.name) ? b["cases"][c.name] : json{{"status", "Skip"}, {"detail", "not in the dump"}};
      const bool ran = st.at("status") == "Pass";
      r.cases.push_back({ran ? Status::Pass : Status::Skip, ran ? "" : "dumped as " + st.at("status").get<std::string>() + ": " +
                                                                           st.value("detail", "")});
    }
    runs.push_back(std::move(r));
  }
  if (runs.empty()) throw Error(ErrorKind::Input, dir.string() + ": the dump holds no backend");
  return runs;
} catch (const json::exception& e) {   // a damaged or foreign manifest: unreadable JSON, a field missing or of another type
  throw Error(ErrorKind::Input, (dir / "manifest.json").string() + ": not a --dump manifest: " + io::oneLine(e.what()));
}

int run(const ParsedArgs& args) {
  const std::vector<std::string> names = args.getList("--backends", "vulkan,gl-egl,gl-osmesa,cpu");
  checkBackendNames(names, kBackendNames);
  const std::vector<std::string> required = args.getList("--require", "");
  for (const std::string& n : required)
    if (std::find(names.begin(), names.end(), n) == names.end())
      throw Error(ErrorKind::Input, "--require: '" + n + "' is not one of --backends");
  const bool against = args.has("--against");
  if (names.size() < (against ? 1u : 2u))
    throw Error(ErrorKind::Input, against ? "--backends needs a backend" : "--backends needs at least two backends to compare");
  const bool fromFile = args.has("--cases");
  if (fromFile == !args.positional.empty())
    throw Error(ErrorKind::Input, "give MESH -l LATTICE or --cases default|FILE, not both (usage: sffd conform " +
                                      std::string(args.command->usage) + ")");
  RunnerOptions options;
  options.timeoutSeconds = args.getDouble("--timeout", 60);
  if (!(options.timeoutSeconds > 0)) throw Error(ErrorKind::Input, "--timeout must be a number of seconds > 0");
  options.deviceSubstring = args.get("--device");
  const std::vector<Case> cases = fromFile ? readCases(args.get("--cases"), dataDir()) : std::vector<Case>{caseFromArgs(args)};
  // The result files must not overwrite what the run reads.
  std::vector<std::string> inputs = {args.get("--baseline"), fromFile && args.get("--cases") != "default" ? args.get("--cases") : ""};
  for (const Case& c : cases) inputs.insert(inputs.end(), {c.args.positional.at(0), c.args.get("--lattice")});
  for (const char* opt : {"--junit", "--json"})
    if (args.has(opt)) checkOutputPath(args.get(opt), inputs, /*renamed=*/false);   // --json /dev/stdout is written

  // A --against folder is read before any work, so that a wrong one fails at once.
  std::vector<BackendRun> dumped = against ? readDump(args.get("--against"), cases) : std::vector<BackendRun>{};
  // The children write the buffers under the dump folder, or a temporary one removed at the end.
  fs::path root;
  if (args.has("--dump")) {
    root = args.get("--dump");
    std::error_code ec, made;
    if (fs::exists(root, ec) && !fs::is_empty(root, ec))
      throw Error(ErrorKind::Input, root.string() + ": the dump folder exists and is not empty");
    fs::create_directories(root, made);
    if (!fs::is_directory(root, ec))
      throw Error(ErrorKind::Input, root.string() + ": cannot make the dump folder: " + (made ? made.message() : "not a folder"));
  } else {
    std::string tmpl = (fs::temp_directory_path() / "sffd_conform_XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) throw Error(ErrorKind::Internal, "cannot create a temporary folder");
    root = tmpl;
  }
  struct Cleanup {
    fs::path dir;
    ~Cleanup() { if (!dir.empty()) fs::remove_all(dir); }
  } cleanup{args.has("--dump") ? fs::path() : root};

  std::vector<BackendRun> runs;
  for (const std::string& n : names) {
    runs.push_back(runBackend(n, cases, root / n, options));
    const BackendRun& r = runs.back();
    if (!r.opened && r.cases.size() && r.cases[0].status == Status::Skip)
      std::fprintf(stderr, "sffd: conform: %s: Skip: %s\n", n.c_str(), r.skipReason.c_str());
    for (size_t i = 0; i < cases.size(); ++i)
      if (r.cases[i].status != Status::Pass && (r.opened || r.cases[i].status != Status::Skip))
        std::fprintf(stderr, "sffd: conform: %s %s: %s: %s\n", r.label.c_str(), cases[i].name.c_str(),
                     statusName(r.cases[i].status), r.cases[i].detail.c_str());
  }
  if (args.has("--dump")) writeManifest(root, cases, runs);

  std::vector<std::pair<size_t, size_t>> pairs;
  const size_t live = runs.size();
  if (against) {
    for (BackendRun& d : dumped) runs.push_back(std::move(d));
    for (size_t i = 0; i < live; ++i) {
      size_t before = pairs.size();
      for (size_t j = live; j < runs.size(); ++j)
        if (runs[j].label == "dump:" + runs[i].label) pairs.push_back({j, i});
      if (pairs.size() == before)   // no dump of the same backend: compare with every dumped one
        for (size_t j = live; j < runs.size(); ++j) pairs.push_back({j, i});
    }
  } else {
    for (size_t i = 0; i < live; ++i)
      for (size_t j = i + 1; j < live; ++j) pairs.push_back({i, j});
  }
  std::vector<Result> results = compareRuns(cases, runs, pairs);
  if (args.has("--baseline")) applyBaseline(results, args.get("--baseline"));
  printText(results, fromFile);
  WrittenFiles written;   // as they were again when the --json cannot be written after the --junit
  if (args.has("--junit")) {
    written.willWrite(args.get("--junit"));
    writeJunit(args.get("--junit"), results);
  }
  if (args.has("--json")) {
    written.willWrite(args.get("--json"));
    writeJson(args.get("--json"), cases, runs, results);
  }
  written.keep();
  bool pass = true;
  for (const Result& r : results) pass = pass && !isFailure(r.status);
  std::printf("conform: %s\n", pass ? "PASS" : "FAIL");
  std::fflush(stdout);
  for (size_t i = 0; i < live; ++i)
    if (!runs[i].opened && std::find(required.begin(), required.end(), runs[i].name) != required.end())
      throw deviceError("required backend " + runs[i].name + " could not be opened: " +
                        (runs[i].skipReason.empty() ? runs[i].cases[0].detail : runs[i].skipReason));
  return pass ? 0 : 1;
}

}  // namespace

CommandSpec conformCommand() {
  CommandSpec c{"conform", "MESH -l LATTICE [options] | --cases default|FILE [options]",
                "Runs the same jobs on several backends and compares every output buffer; exit 1 on a failure.",
                caseSpec().options, run, 0, 1};
  const std::vector<OptionSpec> own = {
      {"--backends", "LIST", "comma-separated backends to compare (default vulkan,gl-egl,gl-osmesa,cpu)"},
      {"--device", "SUBSTRING", "on each backend, the first device whose name contains SUBSTRING"},
      {"--cases", "default|FILE", "run a case set: the default one (every kernel) or a case file"},
      {"--require", "LIST", "backends that must open (exit 3 otherwise); others that cannot are skipped"},
      {"--timeout", "SECONDS", "a backend child without progress for this long is killed: Timeout (default 60; a kernel compile is progress for up to 10 times this)"},
      {"--junit", "FILE", "write JUnit XML: one testcase per case, buffer and pair of backends"},
      {"--json", "FILE", "write the backends, cases and results as JSON"},
      {"--baseline", "FILE", "expected failures, TEST,STATUS lines (deqp-runner's failures.csv)"},
      {"--dump", "DIR", "write every compared buffer and a manifest to DIR (a new or empty folder)"},
      {"--against", "DIR", "compare the backends with the buffers of a --dump folder instead of each other"},
      {"--quiet", nullptr, "no notes on stderr"},
      {"--help|-h", nullptr, "show this help"},
  };
  c.options.insert(c.options.end(), own.begin(), own.end());
  return c;
}

}  // namespace sffd::cli
