// <sffd/vulkan.h>: a Device on the application's Vulkan device, and the VkBuffers of its output.
#include "backends/vulkan/vk_interop.h"

#include <sffd/error.h>

namespace sffd::vulkan {

Device adoptDevice(const DeviceConfig& config) { return Device("vulkan-adopted", vk::adoptBackend(config)); }

BufferRange bufferOf(const Deformer& deformer, const OutputChunk& chunk) {
  Device& device = deformer.device();
  VkBuffer buffer = device.info().api == "vulkan" ? vk::vkBufferOf(device.backend(), chunk.buffer) : VK_NULL_HANDLE;
  if (!buffer)
    throw Error(ErrorKind::Input, "sffd::vulkan::bufferOf: the Deformer runs on " + device.label() +
                                      ", not on a Vulkan device, or the chunk is not its output");
  return {buffer, chunk.offset, chunk.bytes};
}

}  // namespace sffd::vulkan
