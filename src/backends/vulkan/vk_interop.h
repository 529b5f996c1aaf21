// Interop with an application's Vulkan objects (include/sffd/vulkan.h): a backend on its borrowed
// instance, device and queue, and the VkBuffer behind a backend buffer.
#pragma once
#include <memory>

#include "backends/vulkan/vk_loader.h"   // <vulkan/vulkan.h>, before <sffd/vulkan.h>
#include "core/backend.h"
#include <sffd/vulkan.h>

namespace sffd::vk {

// Throws a device Error when the device cannot run the kernels (Vulkan 1.0, no compute on the family).
std::unique_ptr<Backend> adoptBackend(const vulkan::DeviceConfig& config);
// VK_NULL_HANDLE when `backend` is not a Vulkan backend or has no such buffer.
VkBuffer vkBufferOf(const Backend& backend, BufferId buffer);

}  // namespace sffd::vk
