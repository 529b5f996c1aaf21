// The logical device: one compute queue, the device-level function table, and buffer allocation
// with memory types chosen by use, so the same code runs on unified memory (lavapipe, integrated
// GPUs: storage buffers are mapped and written directly) and on discrete GPUs (device-local
// storage, host-visible staging).
#pragma once
#include <cstdint>
#include <optional>

#include "backends/vulkan/vk_instance.h"
#include "backends/vulkan/vk_shader_object.h"

namespace sffd::vk {

enum class MemoryUse {
  Storage,    // kernel data: device-local; also mapped when device-local memory is host-visible
  Upload,     // staging the host writes once
  Download,   // staging the host reads back (cached when possible)
  Params,     // small per-submission parameter ring (host-visible, device-local when possible)
};

// One buffer with its own memory (sffd creates few, large buffers: no sub-allocator needed).
struct Allocation {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  uint64_t size = 0;
  void* mapped = nullptr;   // host pointer when the memory is host-visible and coherent
};

class Device {
 public:
  // Creates the device with shaderFloat64 enabled when the hardware has it, and with
  // VK_EXT_shader_object when `shaderObjects` asks for it on a CPU device (lavapipe) that offers it.
  Device(const Instance& instance, const PhysicalDevice& physical, bool shaderObjects = false);
  // Borrows an application's device and queue (interop; never destroyed here): `physical` describes
  // the queue's family, and its float64 limit says whether shaderFloat64 was enabled.
  Device(const Instance& instance, const PhysicalDevice& physical, VkDevice borrowed, VkQueue queue);
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  const Api& api() const { return api_; }
  VkDevice handle() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return family_; }
  uint32_t timestampBits() const { return timestampBits_; }   // valid bits of the queue's timestamps
  const VkPhysicalDeviceProperties& properties() const { return props_; }
  const DeviceInfo& info() const { return info_; }
  bool owned() const { return owned_; }
  // VK_EXT_shader_object's entry points where it was enabled; null otherwise (and on adopted devices).
  const ShaderObjects* shaderObjects() const { return shaderObjects_ ? &*shaderObjects_ : nullptr; }
  // Leaves the VkDevice alive at destruction: a hung device may still run our work.
  void abandon() { owned_ = false; }

  // Throws a device Error when memory runs out.
  Allocation allocate(uint64_t bytes, VkBufferUsageFlags usage, MemoryUse use);
  void release(Allocation& allocation);

 private:
  uint32_t memoryType(uint32_t allowedTypes, MemoryUse use) const;
  void chooseMemory(VkPhysicalDevice physical);
  void loadShaderObjects(VkPhysicalDevice physical);

  Api api_;
  DeviceInfo info_;
  VkPhysicalDeviceProperties props_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  bool unified_ = false;   // every device-local memory type is host-visible
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t family_ = 0;
  uint32_t timestampBits_ = 0;
  bool owned_ = true;
  std::optional<ShaderObjects> shaderObjects_;
};

}  // namespace sffd::vk
