#include "core/kernel_registry.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "kernels/common/shader_layout.h"

namespace sffd {

const EmbeddedKernel* findKernel(std::string_view name) {
  for (const EmbeddedKernel& k : embeddedKernels())
    if (name == k.name) return &k;
  return nullptr;
}

std::string glslForVariant(const EmbeddedKernel& kernel, KernelVariant variant, bool es) {
  std::string src = es ? kernel.gles : kernel.glsl;
  size_t eol = src.find('\n');
  std::string defines = std::string("#define SFFD_STRICT ") + (variant.strict ? "1" : "0") +
                        "\n#define SFFD_F64 " + (variant.f64 ? "1" : "0") + "\n";
  src.insert(eol == std::string::npos ? src.size() : eol + 1, defines);
  return src;
}

Error noFloat64Error(const DeviceInfo& info) {
  if (info.api == "gles")
    return Error(ErrorKind::Input, "OpenGL ES has no double precision: use --precision float (or auto) with --backend gles");
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

CompileTrace::CompileTrace(std::string_view backend, std::string_view kernel, KernelVariant variant) {
  const char* on = std::getenv("SFFD_TRACE_COMPILE");
  if (!on || !*on || std::string_view(on) == "0") return;
  what_ = std::string(backend) + " " + std::string(kernel) + (variant.strict ? " strict" : " fast") +
          (variant.f64 ? " f64" : " f32");
  start_ = std::chrono::steady_clock::now();
}

CompileTrace::~CompileTrace() {
  if (what_.empty()) return;
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "sffd: compile %s: %.1f ms\n", what_.c_str(), ms);
}

}  // namespace sffd
