#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <future>
#include <optional>
#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "apps/sffd/cli.h"
#include "apps/sffd/conform.h"
#include "core/backend.h"
#include <sffd/error.h>
#include "core/environment_check.h"
#include "core/huge_pages.h"
#include "core/job_budget.h"
#include "io/atomic_file.h"
#include "io/io_util.h"
#include "io/lattice_io.h"
#include "io/mesh_io_internal.h"
#include "model/mesh.h"

namespace sffd::cli {
namespace fs = std::filesystem;

std::vector<OptionSpec> jobOptions() {
  return {
      {"--lattice|-l", "FILE", "lattice: .json (native), .prm (PyGeM) or .npy (reference implementation)"},
      {"--backend", "NAME", "auto|vulkan|gl|gl-egl|gl-osmesa|gl-glfw|gles|cpu (auto: Vulkan, then GL, then CPU; gles: OpenGL ES 3.1)"},
      {"--device", "SUBSTRING", "use the first device whose name contains SUBSTRING"},
      {"--method", "NAME", "smooth|accurate|classic (default smooth)"},
      {"--clip", "NAME", "regular|knot-box sub-triangle clipping (default regular)"},
      {"--edge-length", "L", "target sub-triangle edge length l, in model units (default a tenth of the mesh's largest extent)"},
      {"--tess", "N", "tessellation level of each patch (default 10)"},
      {"--split", nullptr, "smooth: run the deform steps as separate dispatches (per-step timings in --stats)"},
      {"--samples", "S", "smooth: sampling density s of the fit (default nu+nv+nw; 6 is the reference implementation's)"},
      {"--crease-angle", "DEG|auto", "meshes without normals: creases where the dihedral angle exceeds DEG (default auto: above 80, or above 40 and 3 times its neighbours')"},
      {"--ignore-normals", nullptr, "recompute the normals from the winding instead of reading them from the file"},
      {"--bpt-resolution", "N", ".bpt input: grid segments per patch side (default 10: 200 triangles a patch)"},
      {"--normalize", "S", "center the mesh on its box and scale its largest half-extent to S (.npy: 0.99)"},
      {"--degree", "U,V,W", ".npy lattices: B-spline degree per axis (default 2,2,2)"},
      {"--precision", "NAME", "auto|float|double kernel arithmetic (auto: double for classic where supported)"},
      {"--strict", nullptr, "strict kernels: bit-identical across GL, GLES, Vulkan and the CPU reference at one --precision"},
      {"--stats", "FILE", "write run statistics as JSON"},
      {"--quiet", nullptr, "no notes on stderr"},
      {"--help|-h", nullptr, "show this help"},
  };
}

std::string normalsAgainstWindingWarning(const Mesh& mesh, const std::string& path) {
  if (!mesh.normalsFromFile) return {};
  size_t against = 0, judged = 0;
  for (const auto& t : mesh.triangles) {
    const glm::dvec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
    const glm::dvec3 face = glm::cross(b - a, c - a);
    const glm::dvec3 mean = mesh.normals[t[0]] + mesh.normals[t[1]] + mesh.normals[t[2]];
    const double d = glm::dot(face, mean);
    if (d == 0 || !std::isfinite(d)) continue;   // no area, or normals that cancel: no say
    ++judged;
    against += d < 0;
  }
  if (judged == 0 || 2 * against <= judged) return {};
  const int percent = int(std::lround(100.0 * double(against) / double(judged)));
  return path + ": the file's normals point against the winding for " + std::to_string(percent) +
         "% of the triangles; the result follows the normals (--ignore-normals recomputes them from the winding)";
}

void meshBounds(const Mesh& mesh, glm::dvec3& lo, glm::dvec3& hi) {
  lo = glm::dvec3(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (const auto& p : mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
}

void normalizeMesh(Mesh& mesh, double scale) {
  if (mesh.positions.empty()) return;
  glm::dvec3 lo, hi;
  meshBounds(mesh, lo, hi);
  glm::dvec3 c = (lo + hi) * 0.5;
  double half = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}) * 0.5;
  double f = half > 0 ? scale / half : 1.0;
  for (auto& p : mesh.positions) p = (p - c) * f;
  for (auto& patch : mesh.patches)
    for (auto& p : patch.points) p = (p - c) * f;
}


Job loadJob(const ParsedArgs& args) {
  Job job;
  job.meshPath = args.positional.at(0);
  job.latticePath = args.requireValue("--lattice");
  MeshReadOptions read;
  if (args.has("--bpt-resolution")) read.bptResolution = args.getInt("--bpt-resolution", 10, 1, 1000);
  job.mesh = readMeshWarning(job.meshPath, read);
  if (args.has("--ignore-normals") && job.mesh.normalsFromFile) {
    computeVertexNormals(job.mesh);
    job.mesh.normalsFromFile = false;
  } else if (std::string w = normalsAgainstWindingWarning(job.mesh, job.meshPath); !w.empty()) {
    warnOnSuccess(w);
  }
  const std::string ext = io::lowerExtension(job.latticePath);
  if (args.has("--normalize")) {
    double s = args.getDouble("--normalize", 1.0);
    if (!(s > 0)) throw Error(ErrorKind::Input, "--normalize needs a positive scale");
    job.normalizedTo = s;
  } else if (ext == ".npy") {
    job.normalizedTo = 0.99;   // the reference implementation's convention
  }
  if (job.normalizedTo) normalizeMesh(job.mesh, *job.normalizedTo);
  job.lattice = loadJobLattice(args, job, job.latticePath);
  return job;
}

Lattice loadJobLattice(const ParsedArgs& args, const Job& job, const std::string& latticePath) {
  const std::string ext = io::lowerExtension(latticePath);
  // An option that would be ignored is refused (as `sffd lattice --from` does).
  if (args.has("--degree") && ext != ".npy")
    throw Error(ErrorKind::Input, "--degree is a .npy lattice's; " + latticePath + " keeps its own (sffd lattice --from L --elevate raises it)");
  LatticeReadOptions lo;
  lo.npyDegree = args.getTriple("--degree", {2, 2, 2}, 1, 5);
  meshBounds(job.mesh, lo.meshBoxLo, lo.meshBoxHi);
  // .npy (reference implementation): the body box is the model's box normalised into [-1,1]^3 and
  // the model itself sits at the --normalize scale inside it (0.99: strictly inside). The shared
  // identity lattice t_control_points0.npy is exactly the Greville lattice of that box.
  if (ext == ".npy" && job.normalizedTo) {
    lo.meshBoxLo /= *job.normalizedTo;
    lo.meshBoxHi /= *job.normalizedTo;
  }
  lo.haveMeshBox = !job.mesh.positions.empty();
  lo.memoryLimit = memoryLimitFromEnvironment();
  return withToolLimitName([&] { return readLattice(latticePath, lo); });
}

namespace {

// The files a .gltf input reads besides itself: its buffers' URIs (not data: URIs), relative to it.
std::vector<std::string> gltfBufferFiles(const std::string& gltf) {
  std::vector<std::string> files;
  try {
    const nlohmann::json j = nlohmann::json::parse(io::readWholeFile(gltf));
    for (const nlohmann::json& b : j.value("buffers", nlohmann::json::array()))
      if (b.is_object() && b.contains("uri") && b["uri"].is_string() && b["uri"].get<std::string>().rfind("data:", 0) != 0)
        files.push_back((fs::path(gltf).parent_path() / b["uri"].get<std::string>()).string());
  } catch (...) {   // an input that cannot be read is said by its reader
  }
  return files;
}

}  // namespace

void checkOutputPath(const std::string& out, const std::vector<std::string>& inputs, bool renamed) {
  std::error_code ec;
  if (out.empty()) throw Error(ErrorKind::Input, "the output's file name is empty");
  // Fail before any work when the output cannot be written where asked.
  fs::path dir = fs::path(out).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir, ec)) throw Error(ErrorKind::Input, out + ": cannot write: no such directory");
  if (fs::is_directory(out, ec)) throw Error(ErrorKind::Input, out + ": cannot write: is a directory");
  // Outputs are renamed into place: over a FIFO or a device (/dev/stdout, through its link) that would remove
  // it, as root /dev's own entry, and write nothing where asked.
  if (const fs::file_status st = fs::status(out, ec); renamed && fs::exists(st) && !fs::is_regular_file(st))
    throw Error(ErrorKind::Input, out + ": cannot write: not a regular file (a FIFO or a device); give a file");
  // A .gltf's files are its buffers too, and the NAME.bin sffd writes beside it (an output given as an input of
  // a later file, as deform's --stats is checked against its -o).
  std::vector<std::string> files = inputs;
  for (const std::string& in : inputs)
    if (io::lowerExtension(in) == ".gltf") {
      files.push_back(fs::path(in).replace_extension(".bin").string());
      for (const std::string& f : gltfBufferFiles(in)) files.push_back(f);
    }
  for (const std::string& in : files) {
    if (in.empty()) continue;
    if (fs::weakly_canonical(out, ec) == fs::weakly_canonical(in, ec) || (fs::exists(out, ec) && fs::equivalent(out, in, ec)))
      throw Error(ErrorKind::Input, out + ": output path is an input file; refusing to overwrite it");
  }
  if (io::lowerExtension(out) == ".gltf")
    checkOutputPath(fs::path(replacedFile(out)).replace_extension(".bin").string(), files, renamed);
}

bool writtenInPlace(const std::string& file) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(file, ec);
  if (fs::exists(st) && !fs::is_regular_file(st)) return true;
  struct stat named {}, stream {};
  if (::stat(file.c_str(), &named) != 0) return false;
  for (int fd : {1, 2})
    if (::fstat(fd, &stream) == 0 && stream.st_dev == named.st_dev && stream.st_ino == named.st_ino) return true;
  return false;
}

WrittenFiles::~WrittenFiles() {
  for (auto it = files_.rbegin(); it != files_.rend(); ++it) it->undo();   // the latest first, as an interrupt does
}

void WrittenFiles::willWrite(const std::string& path) {
  // The file written, through a link as the writers write (the link stays).
  std::vector<std::string> files = {replacedFile(path)};
  if (io::lowerExtension(path) == ".gltf") files.push_back(fs::path(files[0]).replace_extension(".bin").string());
  for (const std::string& file : files) {
    if (writtenInPlace(file)) continue;
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(file, ec))) {
      files_.emplace_back(file, "", !keptOnInterrupt_);
      continue;
    }
    // Beside it, under a name no user file has; registered before it exists.
    const std::string aside = (fs::path(file).parent_path() / (".sffd-replaced-" + std::to_string(::getpid()) + "-" +
                                                               std::to_string(files_.size())))
                                  .string();
    files_.emplace_back(file, aside, !keptOnInterrupt_);
    // A second link keeps the file in its place until the output is renamed onto it (a reader sees the old
    // file or the new one); where the file system has no links, the file is moved aside meanwhile.
    if (::link(file.c_str(), aside.c_str()) != 0 && std::rename(file.c_str(), aside.c_str()) != 0) {
      const int e = errno;
      files_.pop_back();
      throw Error(ErrorKind::Input, file + ": cannot write: cannot keep the file it replaces aside (" + std::strerror(e) + ")");
    }
  }
}

void WrittenFiles::keep() {
  std::vector<std::string> asides;
  for (const OutputUndo& f : files_) asides.push_back(f.aside());
  files_.clear();   // first: an interrupt from now on leaves the command's outputs
  for (const std::string& aside : asides)
    if (!aside.empty()) std::remove(aside.c_str());
}

Device openDeviceFromArgs(const ParsedArgs& args) {
  DeviceRequest r;
  r.name = args.get("--backend", "auto");
  r.deviceSubstring = args.get("--device");
  std::vector<std::string> notes;
  Device d = Device::open(r, &notes);
  for (const std::string& n : notes) note(args, n);
  return d;
}

JobAndDevice loadJobAndOpenDevice(const ParsedArgs& args) {
  using Clock = std::chrono::steady_clock;
  // Opening a device costs lavapipe and llvmpipe 20-30 ms (the Vulkan loader, LLVM's start-up), about what
  // reading the teapot takes, so the inputs are read on another thread meanwhile. Not a mesh read in a forked
  // child (meshio::readsInForkedChild): forked while this thread is inside the dynamic loader, the child can
  // wait on a lock no thread of its own will release (seen under the sanitizers: ten minutes, until its alarm).
  // Nothing on this thread calls warnOnSuccess (the reader's) before the join.
  std::optional<Job> readFirst;
  std::future<Job> reading;
  if (!args.positional.empty() && meshio::readsInForkedChild(args.positional[0])) readFirst.emplace(loadJob(args));
  else reading = std::async(std::launch::async, [&args] { return loadJob(args); });
  const Clock::time_point t = Clock::now();
  std::optional<Device> device;
  try {
    device.emplace(openDeviceFromArgs(args));
  } catch (...) {
    if (reading.valid()) reading.get();   // the input's error first, as when the inputs were read before the device opened
    throw;
  }
  const double openMs = std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  Job job = readFirst ? std::move(*readFirst) : reading.get();
  return {std::move(job), std::move(*device), openMs};
}

int samplesOf(const ParsedArgs& args) {
  if (!args.has("--samples")) return 0;
  const Error refused(ErrorKind::Input, "option --samples needs an integer 1..15 (below 3 samples as 3), not '" + args.get("--samples", "") + "'");
  int s = 0;
  try {
    s = args.getInt("--samples", 0);
  } catch (const Error&) {
    throw refused;
  }
  if (s < 1 || s > 15) throw refused;
  return s;
}

double creaseAngleOf(const ParsedArgs& args) {
  if (args.get("--crease-angle", "auto") == "auto") return kCreaseAngleAuto;
  const Error refused(ErrorKind::Input, "option --crease-angle needs auto or an angle of 0..180 degrees, not '" +
                                           args.get("--crease-angle", "") + "'");
  double deg = 0;
  try {
    deg = args.getDouble("--crease-angle", 0);
  } catch (const Error&) {
    throw refused;
  }
  // Negative numbers would read as kCreaseAngleAuto; past 180 no edge bends.
  if (deg < 0 || deg > 180) throw refused;
  return deg;
}

void checkEdgeLength(const Mesh& mesh, double l) { checkSubTriangleCount(mesh, l, "--edge-length"); }

uint64_t memoryLimitFromEnvironment() {
  const char* s = std::getenv("SFFD_MEMORY_LIMIT");
  if (!s || !*s) return 0;
  uint64_t v = parseByteSize(s);
  if (v == 0) throw Error(ErrorKind::Input, std::string("SFFD_MEMORY_LIMIT must be a size like 4096, 512M or 2G, not '") + s + "'");
  return v;
}

std::string toolLimitMessage(std::string what) {
  for (const char* name : {"(DeformOptions::memoryLimit)", "(LatticeReadOptions::memoryLimit)", "(the memoryLimit of refineLattice or elevateLattice)"})
    if (size_t at = what.find(name); at != std::string::npos) what.replace(at, std::strlen(name), "(SFFD_MEMORY_LIMIT)");
  // The library's words for the options, the tool's flags for them.
  static const std::pair<const char*, const char*> flags[] = {
      {"a longer edge length or a lower tessellation level", "a longer --edge-length or a lower --tess"},
      {"Precision::Float (or Auto) as DeformOptions::precision on an OpenGL ES device", "--precision float (or auto) with --backend gles"},
      {"float precision (DeformOptions::precision)", "--precision float"},
  };
  for (const auto& [library, tool] : flags)
    if (size_t at = what.find(library); at != std::string::npos) what.replace(at, std::strlen(library), tool);
  return what;
}

namespace {
// A chunk of more elements than 32-bit indices count is bounded by the device's limits anyway.
constexpr uint64_t kMaxChunkVariable = UINT32_MAX;
}  // namespace

size_t chunkFromEnvironment(const char* name) { return size_t(integerVariable(name, 1, kMaxChunkVariable)); }

void checkToolVariables() {
  checkHugePagesVariable();
  memoryLimitFromEnvironment();
  for (const char* name : {"SFFD_MAX_CHUNK_VERTICES", "SFFD_MAX_CHUNK_PATCHES", "SFFD_MAX_CHUNK_TRIANGLES", "SFFD_MAX_CHUNK_SUBTRIANGLES"})
    checkVariableIsInteger(name, 1, kMaxChunkVariable);
  conform::checkConformFaultVariable();
}

void checkBackendNames(const std::vector<std::string>& names, std::span<const std::string_view> known) {
  for (const std::string& n : names)
    if (std::find(known.begin(), known.end(), n) == known.end()) {
      std::string list;
      for (std::string_view k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      throw Error(ErrorKind::Input, "--backends: unknown backend '" + n + "' (" + list + ")");
    }
}

bool wantDouble(const ParsedArgs& args, const DeviceInfo& info, bool autoDouble) {
  std::string p = args.get("--precision", "auto");
  if (p == "float") return false;
  if (p == "double") {
    if (!info.limits.float64) throw noFloat64Error(info);
    return true;
  }
  if (p != "auto") throw Error(ErrorKind::Input, "--precision must be auto, float or double");
  return autoDouble && info.limits.float64;
}

}  // namespace sffd::cli
