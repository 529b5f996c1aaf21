// The Vulkan instance: loader, optional validation layer with its debug messenger, and the physical
// devices described as sffd::DeviceInfo, best first. No logical device is created here, so
// listDevices() is cheap and harmless.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/backend.h"
#include "backends/vulkan/vk_loader.h"

namespace sffd::vk {

struct PhysicalDevice {
  VkPhysicalDevice handle = VK_NULL_HANDLE;
  DeviceInfo info;
  uint32_t computeFamily = UINT32_MAX;   // first queue family with compute
  uint32_t timestampBits = 0;            // its timestampValidBits
  std::string unusable;                  // why sffd cannot run on it; empty when it can
};

// Validation on: the option, or env SFFD_VK_VALIDATION set to anything but "" or "0".
bool validationRequested(bool option);

// Whether the physical device offers a device extension.
bool hasDeviceExtension(const Api& api, VkPhysicalDevice device, const char* name);

class Instance {
 public:
  // Throws a device Error when the loader, an ICD or Vulkan 1.1 is missing.
  explicit Instance(bool validation);
  // Borrows an application's instance (interop): never destroyed here; entry points through
  // `getProc`, or the system loader's when it is null.
  Instance(VkInstance borrowed, PFN_vkGetInstanceProcAddr getProc);
  ~Instance();
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  const Api& api() const { return api_; }
  VkInstance handle() const { return instance_; }
  // Every physical device, sorted discrete, integrated, virtual, CPU, other (stable within a type).
  // Throws a device Error when there is none.
  std::vector<PhysicalDevice> physicalDevices() const;
  // One physical device described, its first compute family picked.
  PhysicalDevice describe(VkPhysicalDevice handle) const;
  bool owned() const { return owned_; }
  // Whether an extension of the given Vulkan header version may be used: the validation layer, when on,
  // must know it (one built with older headers reports every use of it as an error).
  bool validationKnows(uint32_t headerVersion) const {
    return validationLayerVersion_ == 0 || validationLayerVersion_ >= headerVersion;
  }

 private:
  Api api_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  bool owned_ = true;
  uint32_t validationLayerVersion_ = 0;   // the layer's specVersion when it is on
};

}  // namespace sffd::vk
