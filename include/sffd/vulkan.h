// sffd/vulkan.h: sffd on the application's own Vulkan device (interop). Include <vulkan/vulkan.h>
// (or your loader's header, such as volk) before this header.
//
// The application keeps ownership of everything it lends: sffd never destroys the instance, the
// device or the queue, and waits for its own work before a Deformer or Device goes away. The queue
// must not be used by another thread while an sffd call runs (Vulkan's external synchronisation).
// sffd creates (and destroys) its own command pool, buffers, pipelines, descriptor sets and query
// pools on the device. Every sffd call that submits waits for its submission to complete.
//
//   sffd::vulkan::DeviceConfig config{instance, physicalDevice, device, queueFamily, queue,
//                                     vkGetInstanceProcAddr, /*shaderFloat64Enabled=*/false};
//   sffd::Device gpu = sffd::vulkan::adoptDevice(config);
//   sffd::Deformer deformer(gpu, mesh, lattice, {.strict = true});
//   deformer.deform(lattice);
//   for (const sffd::OutputChunk& c : deformer.deviceOutput()) {
//     sffd::vulkan::BufferRange r = sffd::vulkan::bufferOf(deformer, c);   // bind r.buffer at r.offset
//   }
#pragma once
#ifndef VK_VERSION_1_1
#error "include <vulkan/vulkan.h> (Vulkan 1.1 or later) before <sffd/vulkan.h>"
#endif
#include <sffd/deformer.h>
#include <sffd/device.h>

namespace sffd::vulkan {

// The application's device, borrowed. The instance must have been created for Vulkan 1.1 or later;
// timings are measured when the queue family has timestamps.
struct DeviceConfig {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;             // a family with VK_QUEUE_COMPUTE_BIT
  VkQueue queue = VK_NULL_HANDLE;       // a queue of that family
  PFN_vkGetInstanceProcAddr getInstanceProcAddr = nullptr;   // null: sffd opens the system loader
  // Vulkan cannot be asked which features a device was created with: say whether you enabled
  // VkPhysicalDeviceFeatures::shaderFloat64 (double-precision kernels run only then).
  bool shaderFloat64Enabled = false;
};

// A Device on the application's Vulkan device. Throws a device Error when the device cannot run the
// kernels (no compute on the family, Vulkan older than 1.1).
Device adoptDevice(const DeviceConfig& config);

// Where a chunk of a Deformer's device output lives on an adopted (or sffd-made) Vulkan device.
// The buffer is sffd's, valid until the next deform() or the Deformer's end; the last deform()'s
// writes are complete and visible to the application's later submissions on the same queue.
struct BufferRange {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize offset = 0, size = 0;
};
BufferRange bufferOf(const Deformer& deformer, const OutputChunk& chunk);

}  // namespace sffd::vulkan
