#include "backends/vulkan/vk_loader.h"

#include <dlfcn.h>

#include <cstdlib>
#include <string>
#include <string_view>

#include <sffd/error.h>
#include "core/environment_check.h"

namespace sffd::vk {

namespace {

// The loader library is never dlclose'd: ICDs such as lavapipe keep threads and LLVM state that do
// not survive being unloaded and reloaded within one process, and keeping it costs nothing.
void* openLibrary() {
  const char* override = std::getenv("SFFD_VULKAN_LIBRARY");
  std::string name = override && *override ? override : "libvulkan.so.1";
  void* handle = dlopen(name.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle)
    throw deviceError("Vulkan is not available: cannot load the Vulkan loader " + name + " (" + dlerror() + ").");
  return handle;
}

template <typename Fn>
void require(Fn fn, const char* name) {
  if (!fn) throw deviceError(std::string("Vulkan is not usable: the loader has no ") + name + " (Vulkan 1.1 is required).");
}

}  // namespace

Api Api::load() {
  Api api;
  void* library = openLibrary();
  api.vkGetInstanceProcAddr = reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(library, "vkGetInstanceProcAddr"));
  require(api.vkGetInstanceProcAddr, "vkGetInstanceProcAddr");
  api.vkEnumerateInstanceVersion =
      reinterpret_cast<PFN_vkEnumerateInstanceVersion>(api.vkGetInstanceProcAddr(nullptr, "vkEnumerateInstanceVersion"));
#define SFFD_VK_LOAD(name)                                                                  \
  api.name = reinterpret_cast<PFN_##name>(api.vkGetInstanceProcAddr(nullptr, #name)); \
  require(api.name, #name);
  SFFD_VK_GLOBAL_FUNCTIONS(SFFD_VK_LOAD)
#undef SFFD_VK_LOAD
  return api;
}

Api Api::borrow(PFN_vkGetInstanceProcAddr getProc) {
  Api api;
  api.vkGetInstanceProcAddr = getProc;
  api.vkEnumerateInstanceVersion =
      reinterpret_cast<PFN_vkEnumerateInstanceVersion>(getProc(nullptr, "vkEnumerateInstanceVersion"));
#define SFFD_VK_LOAD(name) api.name = reinterpret_cast<PFN_##name>(getProc(nullptr, #name));
  SFFD_VK_GLOBAL_FUNCTIONS(SFFD_VK_LOAD)
#undef SFFD_VK_LOAD
  return api;
}

void Api::loadInstance(VkInstance instance, bool debugUtils) {
#define SFFD_VK_LOAD(name)                                                               \
  name = reinterpret_cast<PFN_##name>(vkGetInstanceProcAddr(instance, #name)); \
  require(name, #name);
  SFFD_VK_INSTANCE_FUNCTIONS(SFFD_VK_LOAD)
  if (debugUtils) {
    SFFD_VK_DEBUG_FUNCTIONS(SFFD_VK_LOAD)
  }
#undef SFFD_VK_LOAD
}

void Api::loadDevice(VkDevice device) {
#define SFFD_VK_LOAD(name)                                                             \
  name = reinterpret_cast<PFN_##name>(vkGetDeviceProcAddr(device, #name)); \
  require(name, #name);
  SFFD_VK_DEVICE_FUNCTIONS(SFFD_VK_LOAD)
#undef SFFD_VK_LOAD
}

bool envFlag(const char* name) {
  const char* value = std::getenv(name);
  return value && std::string_view(value) == "1";
}

void checkVulkanVariables() {
  for (const char* name : {"SFFD_VK_STAGING", "SFFD_VK_VERBOSE", "SFFD_VK_DISABLE_F64", "SFFD_VK_VALIDATION"})
    checkVariableIsOneOf(name, {"0", "1"});
}

const char* resultName(VkResult result) {
  switch (result) {
#define SFFD_VK_RESULT(r) \
  case r:                 \
    return #r;
    SFFD_VK_RESULT(VK_SUCCESS)
    SFFD_VK_RESULT(VK_NOT_READY)
    SFFD_VK_RESULT(VK_TIMEOUT)
    SFFD_VK_RESULT(VK_INCOMPLETE)
    SFFD_VK_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    SFFD_VK_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SFFD_VK_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    SFFD_VK_RESULT(VK_ERROR_DEVICE_LOST)
    SFFD_VK_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    SFFD_VK_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    SFFD_VK_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    SFFD_VK_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    SFFD_VK_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    SFFD_VK_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    SFFD_VK_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    SFFD_VK_RESULT(VK_ERROR_FRAGMENTED_POOL)
    SFFD_VK_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
    SFFD_VK_RESULT(VK_ERROR_UNKNOWN)
#undef SFFD_VK_RESULT
    default:
      return "VkResult error";
  }
}

void check(VkResult result, const char* what) {
  if (result >= 0) return;
  throw deviceError(std::string("Vulkan: ") + what + " failed (" + resultName(result) + ").");
}

}  // namespace sffd::vk
