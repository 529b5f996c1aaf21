// <sffd/vulkan.h>: a Device on the application's Vulkan device, and the VkBuffers of its output.
#include "backends/vulkan/vk_interop.h"

#include <sffd/error.h>

#include "api/output_chunk_check.h"
#include "backends/backend_select.h"

namespace sffd::vulkan {

Device adoptDevice(const DeviceConfig& config) {
  checkLibraryVariables();
  return Device("vulkan-adopted", vk::adoptBackend(config));
}

BufferRange bufferOf(const Deformer& deformer, const OutputChunk& chunk) {
  Device& device = deformer.device();
  checkOutputChunk(deformer, chunk, "sffd::vulkan::bufferOf", device.info().api == "vulkan", "Vulkan");
  VkBuffer buffer = vk::vkBufferOf(device.backend(), chunk.buffer);
  if (!buffer) throw Error(ErrorKind::Internal, "sffd::vulkan::bufferOf: no VkBuffer for an output chunk of the Deformer");
  return {buffer, chunk.offset, chunk.bytes};
}

}  // namespace sffd::vulkan
