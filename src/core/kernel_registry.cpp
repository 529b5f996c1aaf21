#include "core/kernel_registry.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <set>

#include "core/environment_check.h"
#include "kernels/common/shader_layout.h"

namespace sffd {

const EmbeddedKernel* findKernel(std::string_view name) {
  for (const EmbeddedKernel& k : embeddedKernels())
    if (name == k.name) return &k;
  return nullptr;
}

std::span<const uint32_t> spirvFor(const EmbeddedKernel& kernel, KernelVariant variant) {
  const int v = variantIndex(variant);
  for (const SpecializedSpirv& s : kernel.specialized)
    if (s.assumptions == variant.assumptions) return {s.spirv[v], s.spirvWords[v]};
  if (!kernel.spirv[v]) return {};
  return {kernel.spirv[v], kernel.spirvWords[v]};
}

std::string glslForVariant(const EmbeddedKernel& kernel, KernelVariant variant, bool es) {
  std::string src = es ? kernel.gles : kernel.glsl;
  size_t eol = src.find('\n');
  std::string defines = std::string("#define SFFD_STRICT ") + (variant.strict ? "1" : "0") +
                        "\n#define SFFD_F64 " + (variant.f64 ? "1" : "0") +
                        "\n#define SFFD_ASSUMPTIONS " + std::to_string(variant.assumptions) + "u\n";
  src.insert(eol == std::string::npos ? src.size() : eol + 1, defines);
  return src;
}

std::string variantName(KernelVariant v) {
  std::string name = std::string(v.strict ? "strict" : "fast") + (v.f64 ? " f64" : " f32");
  if (v.assumptions) {
    char hex[16];
    std::snprintf(hex, sizeof(hex), "0x%x", unsigned(v.assumptions));
    name += std::string(" assuming ") + hex;
  }
  return name;
}

KernelVariant forLattice(KernelVariant v, const gpu::LatticeParams& lattice) {
  const bool degree2 = lattice.degree.x == 2 && lattice.degree.y == 2 && lattice.degree.z == 2;
  v.assumptions |= degree2 ? SFFD_ASSUME_DEGREE2 : SFFD_ASSUME_GENERAL_DEGREE;
  return v;
}

namespace {
// A kernel whose parameter block may hold the lattice and its constant tables (all of them or none:
// the tables' assumption; some: none, each table's place read at run time).
KernelVariant forInlineLattice(KernelVariant v, const gpu::LatticeParams& lattice, std::initializer_list<uint32_t> tablesAt) {
  v = forLattice(v, lattice);
  v.assumptions |= lattice.break_offset.w ? SFFD_ASSUME_LATTICE_IN_PARAMS : SFFD_ASSUME_LATTICE_IN_STORAGE;
  const size_t inlined = size_t(std::count_if(tablesAt.begin(), tablesAt.end(), [](uint32_t at) { return at != 0; }));
  if (inlined == tablesAt.size()) v.assumptions |= SFFD_ASSUME_FIT_IN_PARAMS;
  else if (inlined == 0) v.assumptions |= SFFD_ASSUME_FIT_IN_STORAGE;
  return v;
}
}  // namespace

KernelVariant forLattice(KernelVariant v, const gpu::DeformParams& params) {
  return forInlineLattice(v, params.lattice, {params.sections.x});
}

KernelVariant forLattice(KernelVariant v, const gpu::AccurateParams& params) {
  return forInlineLattice(v, params.lattice, {params.tables.z, params.tables.w});
}

void checkStrictRoundingVariable() { checkVariableIsOneOf("SFFD_STRICT_ROUNDING", {"fixup", "driver"}); }

KernelVariant forDevice(KernelVariant v, const DeviceInfo& device) {
  const bool llvmpipe = device.name.find("llvmpipe") != std::string::npos;
  if (v.strict) {
    const char* rounding = std::getenv("SFFD_STRICT_ROUNDING");
    const std::string_view r = rounding ? rounding : "";
    if (r == "fixup" || (r != "driver" && !llvmpipe)) v.assumptions |= SFFD_ASSUME_LOOSE_DIVISION;
  }
  const size_t at = device.driver.find("Mesa ");
  const int mesa = at != std::string::npos ? std::atoi(device.driver.c_str() + at + 5) : 0;
  // The one-site form pays only where a one-shot job translates its kernels in every process and runs them
  // once: lavapipe below Mesa 23 (no shader binaries kept; llvmpipe's GL keeps its compiled programs).
  if (!(llvmpipe && device.api == "vulkan" && mesa < 23)) v.assumptions &= ~SFFD_ASSUME_ONE_SAMPLE_SITE;
  if (llvmpipe && mesa >= 23) v.assumptions |= SFFD_ASSUME_ROLLED_LOOPS;
  return v;
}

Error noFloat64Error(const DeviceInfo& info) {
  if (info.api == "gles")
    return Error(ErrorKind::Input, "OpenGL ES has no double precision: use Precision::Float (or Auto) as DeformOptions::precision on an OpenGL ES device");
  // Every GL 4.3 core driver has doubles; the GL backend refuses them where they lose bits (NVIDIA's).
  if (info.api == "gl")
    return deviceError(info.name + ": this OpenGL driver rounds the kernels' doubles to float, so double precision is "
                       "refused on it (docs/CONFORMANCE.md, \"NVIDIA's OpenGL doubles\"); its Vulkan driver runs them");
  return deviceError(info.name + " has no double-precision shader support");
}

void gridFor(uint64_t threads, const DeviceLimits& limits, uint32_t groups[3]) {
  uint64_t need = (threads + SFFD_LOCAL_SIZE - 1) / SFFD_LOCAL_SIZE;
  uint64_t maxX = std::min<uint64_t>(limits.maxWorkGroupCount[0], SFFD_MAX_GROUPS_X);
  if (need == 0) need = 1;
  // Balanced split: rows as few as possible, then columns just enough (no half-empty second row).
  uint64_t y = (need + maxX - 1) / maxX;
  uint64_t x = (need + y - 1) / y;
  groups[0] = static_cast<uint32_t>(x);
  groups[1] = static_cast<uint32_t>(y);
  groups[2] = 1;
}

bool compileTraceOn() {
  static const bool on = [] {
    const char* v = std::getenv("SFFD_TRACE_COMPILE");
    return v && std::string_view(v) == "1";
  }();
  return on;
}

void checkTraceCompileVariable() { checkVariableIsOneOf("SFFD_TRACE_COMPILE", {"0", "1"}); }

void traceFirstDispatch(std::string_view label, double deviceMs) {
  if (!compileTraceOn()) return;
  static std::mutex mutex;
  static std::set<std::string, std::less<>> seen;
  std::lock_guard<std::mutex> lock(mutex);
  if (!seen.insert(std::string(label)).second) return;
  std::fprintf(stderr, "sffd: first dispatch %.*s: %.1f ms\n", int(label.size()), label.data(), deviceMs);
}

namespace {
// The start times of the CompileScopes alive (a few at once: one per precompile worker).
std::mutex gCompilesMutex;
std::multiset<std::chrono::steady_clock::time_point> gCompiles;
}  // namespace

CompileScope::CompileScope(std::string_view backend, std::string_view kernel, KernelVariant variant)
    : start_(std::chrono::steady_clock::now()) {
  {
    std::lock_guard<std::mutex> lock(gCompilesMutex);
    gCompiles.insert(start_);
  }
  if (compileTraceOn()) what_ = std::string(backend) + " " + std::string(kernel) + " " + variantName(variant);
}

CompileScope::~CompileScope() {
  {
    std::lock_guard<std::mutex> lock(gCompilesMutex);
    gCompiles.erase(gCompiles.find(start_));
  }
  if (what_.empty()) return;
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "sffd: compile %s: %.1f ms\n", what_.c_str(), ms);
}

void CompileScope::note(std::string_view words) {
  if (!what_.empty()) what_ += " (" + std::string(words) + ")";
}

double oldestCompileInFlightSeconds() {
  std::lock_guard<std::mutex> lock(gCompilesMutex);
  if (gCompiles.empty()) return -1;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - *gCompiles.begin()).count();
}

}  // namespace sffd
