// The command-line layer: each command is one CommandSpec (its options documented in one line
// each) in its own file, registered in main.cpp.
#pragma once
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <sffd/device.h>
#include <sffd/error.h>

#include "io/atomic_file.h"
#include "model/lattice.h"
#include "model/mesh.h"

namespace sffd::cli {

struct OptionSpec {
  const char* name;    // "--backend" (a short alias follows after '|': "--output|-o")
  const char* value;   // placeholder of its value, nullptr for a flag
  const char* help;    // one line
  bool repeatable = false;   // may be given more than once (ParsedArgs::all); get() is the first value
};

struct ParsedArgs;

struct CommandSpec {
  const char* name;
  const char* usage;     // after "sffd NAME "
  const char* summary;   // one line
  std::vector<OptionSpec> options;
  int (*run)(const ParsedArgs& args);
  size_t minPositional = 0, maxPositional = 1;
};

struct ParsedArgs {
  const CommandSpec* command = nullptr;
  std::vector<std::string> positional;
  std::map<std::string, std::string> values;   // by canonical long name
  std::map<std::string, std::vector<std::string>> repeated;   // repeatable options: every value in order
  std::vector<std::string> all(const std::string& name) const;
  bool has(const std::string& name) const { return values.count(name) > 0; }
  std::string get(const std::string& name, const std::string& fallback = "") const;
  double getDouble(const std::string& name, double fallback) const;
  int getInt(const std::string& name, int fallback) const;
  // An integer lo..hi; anything else is refused with a message that names the range.
  int getInt(const std::string& name, int fallback, int lo, int hi) const;
  // One integer lo..hi for every axis, or three (docs/CLI.md).
  std::array<int, 3> getTriple(const std::string& name, std::array<int, 3> fallback, int lo, int hi) const;
  // A comma-separated list of names (--backends, --require); an empty name ("cpu,", "a,,b") is refused.
  std::vector<std::string> getList(const std::string& name, const std::string& fallback) const;
  std::string requireValue(const std::string& name) const;
};

// Throws an input Error for unknown options, missing values and wrong positional counts.
ParsedArgs parseArgs(const CommandSpec& spec, int argc, char** argv);
std::string helpText(const CommandSpec& spec);

// Options shared by the commands that run a job, as OptionSpecs to splice into a command's list.
std::vector<OptionSpec> jobOptions();

// A mesh and lattice loaded as the options say (--normalize, .npy conventions, --degree).
struct Job {
  std::string meshPath, latticePath;
  Mesh mesh;
  Lattice lattice;
  std::optional<double> normalizedTo;   // the --normalize scale applied to the mesh
};
Job loadJob(const ParsedArgs& args);
// Another lattice for `job`, read with the same conventions as its own (--degree, the .npy box).
Lattice loadJobLattice(const ParsedArgs& args, const Job& job, const std::string& latticePath);

// A warning when the file's normals contradict the winding for most triangles (each face's geometric
// normal against the mean of its corners' file normals); empty otherwise or without file normals.
std::string normalsAgainstWindingWarning(const Mesh& mesh, const std::string& path);

// Centers the mesh on its bounding box and scales it so its largest half-extent is `scale`.
void normalizeMesh(Mesh& mesh, double scale);
void meshBounds(const Mesh& mesh, glm::dvec3& lo, glm::dvec3& hi);

// Refuses an output path that is one of the inputs (nothing is ever written over an input), and, for an
// output `renamed` into place (every writer's but conform's reports, written in place), an existing one that
// is no regular file.
void checkOutputPath(const std::string& out, const std::vector<std::string>& inputs, bool renamed = true);

// The files a command writes, as they were again when it fails before keep() (a later file that cannot be
// written, a later frame that fails; an interrupt too, unless `keptOnInterrupt`): a failed command leaves
// nothing, not even whole files, and takes none of the user's away (a --stats that failed took away the
// output file it had replaced).
class WrittenFiles {
 public:
  explicit WrittenFiles(bool keptOnInterrupt = false) : keptOnInterrupt_(keptOnInterrupt) {}
  WrittenFiles(const WrittenFiles&) = delete;
  WrittenFiles& operator=(const WrittenFiles&) = delete;
  ~WrittenFiles();
  // Before `path` is written (a .gltf's .bin beside it too): a file there is kept aside, put back when the
  // command fails and dropped by keep(); a file made there is removed then.
  void willWrite(const std::string& path);
  void keep();

 private:
  bool keptOnInterrupt_;
  std::vector<OutputUndo> files_;
};

// Whether an output to `file` (a link not followed: the file replacedFile() names) is written in place, not
// through a temporary renamed onto it: a device, a FIFO, the file stdout or stderr goes to (--json /dev/stdout
// > log). The shell's or the system's, no file of the command's: never kept aside, moved or removed.
bool writtenInPlace(const std::string& file);

// Opens the device the options ask for (--backend, --device), printing fallback notes unless --quiet.
Device openDeviceFromArgs(const ParsedArgs& args);

// loadJob and openDeviceFromArgs at once: the inputs are read on a thread while the device opens on the
// caller's (where a GL context is current). An input error wins over a device error, as when one came first.
struct JobAndDevice {
  Job job;
  Device device;
  double openMs = 0;   // the device's opening; the rest of the call is the wait for the inputs after it
};
JobAndDevice loadJobAndOpenDevice(const ParsedArgs& args);

// --precision auto|float|double resolved for a backend (auto: double where the device has it).
bool wantDouble(const ParsedArgs& args, const DeviceInfo& info, bool autoDouble);

// An input Error "--backends: unknown backend 'x' (a, b, c)" for the first of `names` not among `known`, the
// names a command's --backends takes (bench's, conform's), listed in the message in their order.
void checkBackendNames(const std::vector<std::string>& names, std::span<const std::string_view> known);

void note(const ParsedArgs& args, const std::string& line);   // stderr unless --quiet
// A warning about the result or the input ("sffd: warning: LINE" on stderr, even with --quiet), printed
// once the command has succeeded: a command that fails prints its one error line only.
void warnOnSuccess(const std::string& line);
// The warnings so far, in order, taken (main prints them when the command returns 0).
std::vector<std::string> takeWarnings();
// Reads a mesh; what the reader repaired or skipped becomes warnings (warnOnSuccess).
Mesh readMeshWarning(const std::string& path, const MeshReadOptions& options = {});

// SFFD_MEMORY_LIMIT as bytes (0 when unset: physical memory); an input Error when it does not parse.
uint64_t memoryLimitFromEnvironment();
// Runs `f`, naming a memory limit the library reports as one of its options SFFD_MEMORY_LIMIT instead.
template <class F>
auto withToolLimitName(F&& f) -> decltype(f());
// The message of `e` in the tool's words: the library's name of the limit replaced by SFFD_MEMORY_LIMIT, its
// names of options (DeformOptions fields) by the flags that set them.
std::string toolLimitMessage(std::string what);

// SFFD_MAX_CHUNK_* (elements per chunk, to test chunking): the value of the variable `name`, an integer
// 1..4294967295; 0 when it is not set (no limit).
size_t chunkFromEnvironment(const char* name);
// An input Error naming the first variable only the tool reads (SFFD_HUGE_PAGES, SFFD_MEMORY_LIMIT,
// SFFD_MAX_CHUNK_*, SFFD_CONFORM_FAULT) set to a value docs/CLI.md does not give it; main() makes it,
// after checkLibraryVariables, before a command runs.
void checkToolVariables();

// --crease-angle DEG|auto: the threshold for meshes without normals, kCreaseAngleAuto when the option
// is absent or auto; a number must be 0..180 degrees (an input Error otherwise).
double creaseAngleOf(const ParsedArgs& args);

// --samples S: the fit's sampling density, 1..15 as DeformOptions::samples takes it (below 3 is 3); 0, the
// library's nu+nv+nw, when the option is absent. An input Error otherwise.
int samplesOf(const ParsedArgs& args);

// Refuses a target edge length that is not positive, or so small that the sub-triangles would
// exceed kMaxSubTriangles (job_budget.h; the message gives the estimate).
void checkEdgeLength(const Mesh& mesh, double l);

// Picture options shared by render and view (cmd_render.cpp): --width/--height in 16..8192 pixels,
// --view AZIMUTH,ELEVATION in degrees. Throw an input Error otherwise.
int sizeOption(const ParsedArgs& args, const char* name, int fallback);
void parseView(const std::string& text, double& az, double& el);

// The commands, one file each.
CommandSpec deformCommand();
CommandSpec latticeCommand();
CommandSpec devicesCommand();
CommandSpec conformCommand();
CommandSpec clipCommand();
CommandSpec errorCommand();
CommandSpec renderCommand();
CommandSpec benchCommand();
CommandSpec viewCommand();
CommandSpec animateCommand();   // cmd_animate.cpp   // cmd_view.cpp (src/view)

template <class F>
auto withToolLimitName(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const Error& e) {
    std::string what = toolLimitMessage(e.what());
    if (what == e.what()) throw;
    throw Error(e.kind(), what);
  }
}

}  // namespace sffd::cli
