// <sffd/vulkan.h>: a Device on the application's Vulkan device.
#include "backends/vulkan/vk_interop.h"

namespace sffd::vulkan {

Device adoptDevice(const DeviceConfig& config) { return Device("vulkan-adopted", vk::adoptBackend(config)); }

}  // namespace sffd::vulkan
