// Run-time loading of Vulkan: libvulkan.so.1 is dlopen'ed (never linked), so the library and the CLI
// start on machines without Vulkan and report a device Error instead of failing to load.
// Every entry point sffd uses is listed once below (X-macros) and resolved into an `Api` table:
// global ones before an instance exists, instance ones from the instance, device ones from the device.
#pragma once
#ifndef VK_NO_PROTOTYPES
#define VK_NO_PROTOTYPES
#endif
#include <vulkan/vulkan.h>

namespace sffd::vk {

// Resolved with a null instance.
#define SFFD_VK_GLOBAL_FUNCTIONS(X)         \
  X(vkCreateInstance)                       \
  X(vkEnumerateInstanceLayerProperties)     \
  X(vkEnumerateInstanceExtensionProperties)

// Resolved from the instance (core 1.0/1.1).
#define SFFD_VK_INSTANCE_FUNCTIONS(X)          \
  X(vkDestroyInstance)                         \
  X(vkEnumeratePhysicalDevices)                \
  X(vkEnumerateDeviceExtensionProperties)      \
  X(vkGetPhysicalDeviceProperties)             \
  X(vkGetPhysicalDeviceProperties2)            \
  X(vkGetPhysicalDeviceFeatures)               \
  X(vkGetPhysicalDeviceFeatures2)              \
  X(vkGetPhysicalDeviceQueueFamilyProperties)  \
  X(vkGetPhysicalDeviceMemoryProperties)       \
  X(vkCreateDevice)                            \
  X(vkGetDeviceProcAddr)

// VK_EXT_debug_utils: resolved only when validation is on (null otherwise).
#define SFFD_VK_DEBUG_FUNCTIONS(X)   \
  X(vkCreateDebugUtilsMessengerEXT)  \
  X(vkDestroyDebugUtilsMessengerEXT)

// Resolved from the logical device (no loader trampoline on the hot path).
#define SFFD_VK_DEVICE_FUNCTIONS(X)    \
  X(vkDestroyDevice)                   \
  X(vkGetDeviceQueue)                  \
  X(vkDeviceWaitIdle)                  \
  X(vkQueueWaitIdle)                   \
  X(vkCreateBuffer)                    \
  X(vkDestroyBuffer)                   \
  X(vkGetBufferMemoryRequirements)     \
  X(vkAllocateMemory)                  \
  X(vkFreeMemory)                      \
  X(vkBindBufferMemory)                \
  X(vkMapMemory)                       \
  X(vkUnmapMemory)                     \
  X(vkCreateShaderModule)              \
  X(vkDestroyShaderModule)             \
  X(vkCreatePipelineCache)             \
  X(vkDestroyPipelineCache)            \
  X(vkCreateComputePipelines)          \
  X(vkDestroyPipeline)                 \
  X(vkCreateDescriptorSetLayout)       \
  X(vkDestroyDescriptorSetLayout)      \
  X(vkCreatePipelineLayout)            \
  X(vkDestroyPipelineLayout)           \
  X(vkCreateDescriptorPool)            \
  X(vkDestroyDescriptorPool)           \
  X(vkResetDescriptorPool)             \
  X(vkAllocateDescriptorSets)          \
  X(vkUpdateDescriptorSets)            \
  X(vkCreateCommandPool)               \
  X(vkDestroyCommandPool)              \
  X(vkResetCommandPool)                \
  X(vkAllocateCommandBuffers)          \
  X(vkBeginCommandBuffer)              \
  X(vkEndCommandBuffer)                \
  X(vkCmdBindPipeline)                 \
  X(vkCmdBindDescriptorSets)           \
  X(vkCmdDispatch)                     \
  X(vkCmdPipelineBarrier)              \
  X(vkCmdCopyBuffer)                   \
  X(vkCmdResetQueryPool)               \
  X(vkCmdWriteTimestamp)               \
  X(vkCreateQueryPool)                 \
  X(vkDestroyQueryPool)                \
  X(vkGetQueryPoolResults)             \
  X(vkCreateFence)                     \
  X(vkDestroyFence)                    \
  X(vkResetFences)                     \
  X(vkWaitForFences)                   \
  X(vkQueueSubmit)

// The function table. Filled in three steps as the objects it needs come to exist.
struct Api {
  PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
  PFN_vkEnumerateInstanceVersion vkEnumerateInstanceVersion = nullptr;   // null on a 1.0 loader
#define SFFD_VK_DECLARE(name) PFN_##name name = nullptr;
  SFFD_VK_GLOBAL_FUNCTIONS(SFFD_VK_DECLARE)
  SFFD_VK_INSTANCE_FUNCTIONS(SFFD_VK_DECLARE)
  SFFD_VK_DEBUG_FUNCTIONS(SFFD_VK_DECLARE)
  SFFD_VK_DEVICE_FUNCTIONS(SFFD_VK_DECLARE)
#undef SFFD_VK_DECLARE

  // Opens the loader library (env SFFD_VULKAN_LIBRARY overrides "libvulkan.so.1") and resolves the
  // global functions. Throws a device Error when the library or an entry point is missing.
  static Api load();
  // The table of an application's loader (interop): everything resolved through `getProc`; the
  // global functions are not required (sffd creates no instance then).
  static Api borrow(PFN_vkGetInstanceProcAddr getProc);
  void loadInstance(VkInstance instance, bool debugUtils);
  void loadDevice(VkDevice device);
};

// Whether env `name`, one of the Vulkan backend's switches (SFFD_VK_STAGING, SFFD_VK_VERBOSE, SFFD_VK_DISABLE_F64,
// SFFD_VK_VALIDATION), is 1. Never throws (the debug callback reads one): checkVulkanVariables refuses a value
// but 0 or 1 before any work.
bool envFlag(const char* name);
void checkVulkanVariables();

// A zero-initialised Vulkan struct with its sType set.
template <typename T>
T vkStruct(VkStructureType type) {
  T value{};
  value.sType = type;
  return value;
}

// "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc.
const char* resultName(VkResult result);
// Throws a device Error "Vulkan: <what> failed (<result>)" for any negative result.
void check(VkResult result, const char* what);

}  // namespace sffd::vk
