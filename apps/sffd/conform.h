// sffd conform, in parts: the cases and the buffers each runs (cmd_conform_cases.cpp), one child
// process per backend that writes those buffers to files (cmd_conform_runner.cpp), the comparison and
// the reports (cmd_conform_report.cpp), and the command that ties them (cmd_conform.cpp).
// docs/CONFORMANCE.md describes the whole.
#pragma once
#include <filesystem>
#include <map>
#include <optional>
#include <string_view>
#include <string>
#include <vector>

#include "analysis/buffer_compare.h"
#include "apps/sffd/cli.h"

namespace sffd::cli::conform {

namespace fs = std::filesystem;

// One named job: its arguments are those of `sffd conform MESH -l LATTICE [options]`.
struct Case {
  std::string name;
  std::vector<std::string> argv;   // what parseArgs reads; paths already resolved
  ParsedArgs args;                 // parsed from argv (its command spec is caseSpec())
  std::string method() const { return args.get("--method", "smooth"); }
  bool strict() const { return args.has("--strict"); }
  bool f64() const { return args.get("--precision", "float") == "double"; }
  std::string variant() const;     // "strict float", "fast double", ...
};

// The options a case may carry (the job options less those conform does not use).
const CommandSpec& caseSpec();
// A case from the command line's MESH and job options, named after the mesh's file stem.
Case caseFromArgs(const ParsedArgs& args);
// "default" (tests/data/conform/default.cases, found as docs/CONFORMANCE.md says) or a case file: one
// case a line, `NAME MESH -l LATTICE [options]`, `#` comments, paths relative to the file.
std::vector<Case> readCases(const std::string& spec, const std::string& dataDir);
// FNV-1a 64 of the case's input files, "mesh:HEX lattice:HEX": a dump is compared only with the same inputs.
std::map<std::string, std::string> inputHashes(const Case& c);

// One compared output buffer. `perUnit` values describe one unit ("vertex", "triangle",
// "sub-triangle", "patch"); values are as the kernel wrote them, widened to double.
struct Buffer {
  std::string name;   // stage.buffer: "pn.records", "deform.tess.positions", "accurate.patches", ...
  std::string unit;
  size_t perUnit = 4;
  std::vector<double> values;
};
struct CaseOutput {
  std::vector<Buffer> buffers;
  std::vector<uint32_t> parents;   // per sub-triangle or patch: its input triangle (empty for classic)
};

// The buffers runCase writes for the case's method, in its order.
std::vector<std::string> bufferNames(const Case& c);
// Runs every kernel of the case's method on `device` and downloads every output.
CaseOutput runCase(Device& device, const Case& c);

// Buffers on disk: DIR/buffers.json (names, units, counts) and DIR/<name>.f64 (little-endian doubles).
void writeCaseOutput(const fs::path& dir, const CaseOutput& out);
CaseOutput readCaseOutput(const fs::path& dir);

// What became of one case on one backend.
enum class Status { Pass, Fail, Skip, Crash, Timeout, ExpectedFail, UnexpectedPass };
const char* statusName(Status s);
bool isFailure(Status s);   // Fail, Crash, Timeout, UnexpectedPass: exit 1

struct CaseRun {
  Status status = Status::Skip;   // Pass: ran, its buffers are in the run's folder
  std::string detail;             // why it did not run: the skip reason, the signal, the timeout
};

struct BackendRun {
  std::string name;                  // as asked (--backends) or as dumped ("dump:vulkan")
  std::string label;                 // the device's label once opened
  bool opened = false;
  DeviceInfo info;
  std::string skipReason;            // why it could not be opened
  fs::path dir;                      // DIR/<case>/ holds each case's buffers
  std::vector<CaseRun> cases;        // in the order of the cases
};

struct RunnerOptions {
  double timeoutSeconds = 60;   // per case: no progress for that long is a Timeout
  std::string deviceSubstring;
};

// The names --backends takes (and SFFD_CONFORM_FAULT's BACKEND), in the order its message lists them.
inline constexpr std::string_view kBackendNames[] = {"vulkan", "gl", "gl-egl", "gl-osmesa", "gl-glfw", "gles", "cpu"};

// An input Error when the test hook SFFD_CONFORM_FAULT (docs/CONFORMANCE.md) is set to a value that names no
// fault (one it injected none for before).
void checkConformFaultVariable();

// Runs the cases on backend `name` in child processes (a crash or a hang ends one case, and a new
// child goes on with the next), each writing its buffers under `dir`.
BackendRun runBackend(const std::string& name, const std::vector<Case>& cases, const fs::path& dir,
                      const RunnerOptions& options);

// One compared case x buffer x pair of backends.
struct FirstMismatch {
  size_t element = 0;   // index in the buffer
  std::string where;    // "sub-triangle 4 (input triangle 1), value 12 (y)"
  double a = 0, b = 0;
  uint64_t ulp = 0;
};
struct Result {
  std::string test;   // CASE/BUFFER/A-vs-B: the name in JUnit and baselines
  std::string caseName, buffer, a, b;
  Status status = Status::Pass;
  CompareResult compare;
  bool compared = false;   // the numbers above are meaningful
  CompareTolerance tolerance;
  std::optional<FirstMismatch> first;
  std::string message;     // for Fail, Skip, Crash, Timeout
};

// Every buffer of every case, for each pair (a, b) of `pairs` (indices into `runs`).
std::vector<Result> compareRuns(const std::vector<Case>& cases, const std::vector<BackendRun>& runs,
                                const std::vector<std::pair<size_t, size_t>>& pairs);
// deqp-runner's failures.csv: `test,status` lines; listed failures become ExpectedFail, listed tests
// that pass UnexpectedPass.
void applyBaseline(std::vector<Result>& results, const std::string& path);

// The contract's text lines (docs/CLI.md); `prefixCase`: buffers named CASE/BUFFER.
void printText(const std::vector<Result>& results, bool prefixCase);
void writeJunit(const std::string& path, const std::vector<Result>& results);
void writeJson(const std::string& path, const std::vector<Case>& cases, const std::vector<BackendRun>& runs,
               const std::vector<Result>& results);
// The device as JSON (sffd devices --json, the results and the dump manifest).
std::string deviceJson(const std::string& label, const DeviceInfo& info);

}  // namespace sffd::cli::conform
