// Opening a compute backend by name (--backend auto|vulkan|gl|cpu, --device SUBSTRING) with the
// documented fallback order for auto: Vulkan, then GL (EGL, then OSMesa), then the CPU backend.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/backend.h"

namespace sffd {

// A named way to run a job.
struct OpenedBackend {
  std::string label;            // "vulkan", "gl-egl", "gl-osmesa", "gl-glfw", "gles", "cpu"
  DeviceInfo info;
  std::unique_ptr<Backend> backend;
};

struct BackendRequest {
  std::string name = "auto";    // auto, vulkan, gl, gl-egl, gl-osmesa, gl-glfw, gles, cpu
  std::string device;           // device-name substring
  bool validation = false;      // Vulkan validation layer
  bool deviceLimits = false;    // gles: the device's own limits instead of the ES 3.1 minima
  std::string shaderCache = {}; // Vulkan: "" default folder, "none", or a folder (DeviceRequest::shaderCache)
};

// An input Error naming the first SFFD_* variable the library reads that is set to a value docs/CLI.md
// ("Environment variables") does not give it, where it would be taken silently as a default or as "on".
// openBackend, listBackends and the adopting calls make it first; the tool before a command runs.
void checkLibraryVariables();

// Opens the backend; throws a device Error (exit 3) when the one asked for is unusable. For "auto",
// failures are skipped and `notes` receives one line per skipped backend.
OpenedBackend openBackend(const BackendRequest& request, std::vector<std::string>* notes = nullptr);

// Every backend and device that can be used here; `problems` receives one line per API that failed.
std::vector<std::pair<std::string, DeviceInfo>> listBackends(std::vector<std::string>& problems);

}  // namespace sffd
