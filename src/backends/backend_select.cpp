#include "backend_select.h"

#include <sffd/error.h>
#include "backends/cpu/cpu_backend.h"
#include "backends/opengl/gl_backend.h"
#include "backends/vulkan/vk_backend.h"
#include "backends/vulkan/vk_loader.h"
#include "core/device_timeout.h"
#include "core/kernel_registry.h"
#include "core/shader_binary_cache.h"

namespace sffd {

namespace {

OpenedBackend openGl(gl::Provider provider, const std::string& label, const BackendRequest& r) {
  gl::Options o;
  o.provider = provider;
  o.deviceSubstring = r.device;
  o.deviceLimits = r.deviceLimits;
  OpenedBackend b;
  b.backend = gl::createBackend(o);
  b.info = b.backend->info();
  b.label = label == "gl" ? "gl-" + b.info.provider : label;
  return b;
}

OpenedBackend openNamed(const std::string& name, const BackendRequest& r) {
  if (name == "vulkan") {
    vk::Options o;
    o.deviceSubstring = r.device;
    o.validation = r.validation;
    o.shaderCache = r.shaderCache;
    OpenedBackend b;
    b.backend = vk::createBackend(o);
    b.info = b.backend->info();
    b.label = "vulkan";
    return b;
  }
  if (name == "gl") return openGl(gl::Provider::Auto, name, r);
  if (name == "gl-egl") return openGl(gl::Provider::EGL, name, r);
  if (name == "gl-osmesa") return openGl(gl::Provider::OSMesa, name, r);
  if (name == "gl-glfw") return openGl(gl::Provider::GLFW, name, r);
  if (name == "gles") return openGl(gl::Provider::EGLES, name, r);
  if (name == "cpu") {
    OpenedBackend b;
    b.backend = cpu::createBackend();
    b.info = b.backend->info();
    b.label = "cpu";
    return b;
  }
  throw Error(ErrorKind::Input, "unknown backend '" + name + "' (auto, vulkan, gl, gl-egl, gl-osmesa, gl-glfw, gles, cpu)");
}

}  // namespace

void checkLibraryVariables() {
  checkDeviceTimeoutVariable();
  checkCpuThreadsVariable();
  checkCpuAvx2Variable();
  checkShaderCacheDisableVariable();
  checkStrictRoundingVariable();
  checkTraceCompileVariable();
  vk::checkVulkanVariables();
  gl::checkGlProviderVariable();
  gl::checkGlesLimitsVariable();
}

OpenedBackend openBackend(const BackendRequest& r, std::vector<std::string>* notes) {
  checkLibraryVariables();
  if (r.name != "auto") return openNamed(r.name, r);
  for (const char* name : {"vulkan", "gl"}) {
    try {
      return openNamed(name, r);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::Device) throw;
      if (notes) notes->push_back(std::string(name) + " unavailable: " + e.what());
    }
  }
  if (!r.device.empty()) throw deviceError("no Vulkan or GL device matches '" + r.device + "'");
  return openNamed("cpu", r);
}

std::vector<std::pair<std::string, DeviceInfo>> listBackends(std::vector<std::string>& problems) {
  checkLibraryVariables();
  std::vector<std::pair<std::string, DeviceInfo>> out;
  try {
    for (DeviceInfo& d : vk::listDevices()) out.emplace_back("vulkan", d);
  } catch (const Error& e) {
    problems.push_back(std::string("vulkan: ") + e.what());
  }
  try {
    for (DeviceInfo& d : gl::listDevices()) out.emplace_back("gl-" + d.provider, d);
  } catch (const Error& e) {
    problems.push_back(std::string("gl: ") + e.what());
  }
  try {
    gl::Options o;
    o.provider = gl::Provider::EGLES;
    out.emplace_back("gles", gl::createBackend(o)->info());
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Device) throw;
    problems.push_back(std::string("gles: ") + e.what());
  }
  out.emplace_back("cpu", cpu::deviceInfo());
  return out;
}

}  // namespace sffd
