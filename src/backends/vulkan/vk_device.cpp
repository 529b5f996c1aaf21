#include "backends/vulkan/vk_device.h"

#include <atomic>
#include <bit>
#include <cstring>
#include <type_traits>
#include <string>
#include <vector>

#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>
#include <cerrno>

#include <sffd/error.h>
#include "core/huge_pages.h"
#include "backends/vulkan/vk_backend.h"

namespace sffd::vk {

namespace {

constexpr VkMemoryPropertyFlags kMappable = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
// Memory types sffd never uses: they need features or extensions it does not enable.
constexpr VkMemoryPropertyFlags kExcluded = VK_MEMORY_PROPERTY_LAZILY_ALLOCATED_BIT | VK_MEMORY_PROPERTY_PROTECTED_BIT |
                                            VK_MEMORY_PROPERTY_DEVICE_COHERENT_BIT_AMD;

std::atomic<size_t> gAllocations{0};   // deviceMemoryAllocations()

// Whether the mapped device memory [data, data + bytes) is there to touch. lavapipe (Mesa 25.0) keeps
// device memory in one memory file that it grows with ftruncate without checking the result: under a
// file size limit (ulimit -f) the growth fails, the allocation and the map succeed, and the first touch
// past the file's end is a SIGBUS. Populating the range's last page (it ends the file) fails with
// EFAULT there instead of faulting. True where the kernel cannot tell (before Linux 5.14).
bool mappedMemoryIsThere(const void* data, size_t bytes) {
#ifdef MADV_POPULATE_READ
  if (!data || bytes == 0) return true;
  const uintptr_t page = uintptr_t(::sysconf(_SC_PAGESIZE));
  const uintptr_t last = (uintptr_t(data) + bytes - 1) & ~(page - 1);
  return ::madvise(reinterpret_cast<void*>(last), page, MADV_POPULATE_READ) == 0 || errno != EFAULT;
#else
  (void)data, (void)bytes;
  return true;
#endif
}

// The error for device memory the driver could not back: names the file size limit where there is one.
Error unbackedMemoryError(uint64_t bytes) {
  std::string why = "its memory file could not grow";
  struct rlimit limit {};
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    why += " past the file size limit (ulimit -f: " + std::to_string(uint64_t(limit.rlim_cur) / 1024) +
           " KiB); raise it, or use another backend";
  else
    why += " (is memory full?)";
  return deviceError("Vulkan: the driver gave a buffer of " + std::to_string(bytes) + " bytes without memory behind it: " + why + ".");
}

}  // namespace

size_t deviceMemoryAllocations() { return gAllocations.load(); }

namespace {

// Whether the device offers shader objects: the extension, the one it needs below Vulkan 1.3 (sffd's
// instance asks for 1.2), and the feature.
bool offersShaderObjects(const Api& api, VkPhysicalDevice physical) {
  if (!hasDeviceExtension(api, physical, "VK_EXT_shader_object") ||
      !hasDeviceExtension(api, physical, VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME))
    return false;
  auto objects = vkStruct<VkPhysicalDeviceShaderObjectFeaturesEXT>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_OBJECT_FEATURES_EXT);
  auto rendering = vkStruct<VkPhysicalDeviceDynamicRenderingFeaturesKHR>(
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES_KHR);
  rendering.pNext = &objects;
  auto features = vkStruct<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
  features.pNext = &rendering;
  api.vkGetPhysicalDeviceFeatures2(physical, &features);
  return objects.shaderObject && rendering.dynamicRendering;
}

}  // namespace

Device::Device(const Instance& instance, const PhysicalDevice& physical, bool shaderObjects)
    : api_(instance.api()), info_(physical.info), family_(physical.computeFamily), timestampBits_(physical.timestampBits) {
  chooseMemory(physical.handle);

  float priority = 1.0f;
  auto queueInfo = vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  queueInfo.queueFamilyIndex = family_;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;

  VkPhysicalDeviceFeatures features{};
  features.shaderFloat64 = info_.limits.float64 ? VK_TRUE : VK_FALSE;

  // A portability-subset device (MoltenVK) must have the extension enabled to be used at all.
  std::vector<const char*> extensions;
  if (hasDeviceExtension(api_, physical.handle, "VK_KHR_portability_subset"))
    extensions.push_back("VK_KHR_portability_subset");

  // Shader objects (VK_EXT_shader_object), so that kernels can be made from the driver's own binaries,
  // on CPU devices only: lavapipe keeps no translation of a kernel between processes by itself, while GPU
  // drivers keep whole pipelines in their own disk caches (NVIDIA's, Mesa's radv and anv), where shader
  // objects would gain nothing and add a path no GPU run has tested. The extension needs dynamic rendering
  // enabled with it, though compute never renders.
  auto objectFeatures =
      vkStruct<VkPhysicalDeviceShaderObjectFeaturesEXT>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_OBJECT_FEATURES_EXT);
  auto renderingFeatures = vkStruct<VkPhysicalDeviceDynamicRenderingFeaturesKHR>(
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES_KHR);
  shaderObjects = shaderObjects && info_.type == "cpu" && offersShaderObjects(api_, physical.handle);
  if (shaderObjects) {
    extensions.push_back("VK_EXT_shader_object");
    extensions.push_back(VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME);
    objectFeatures.shaderObject = VK_TRUE;
    renderingFeatures.dynamicRendering = VK_TRUE;
    renderingFeatures.pNext = &objectFeatures;
  }

  auto ci = vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
  if (shaderObjects) ci.pNext = &renderingFeatures;
  ci.queueCreateInfoCount = 1;
  ci.pQueueCreateInfos = &queueInfo;
  ci.pEnabledFeatures = &features;
  ci.enabledExtensionCount = uint32_t(extensions.size());
  ci.ppEnabledExtensionNames = extensions.data();
  check(api_.vkCreateDevice(physical.handle, &ci, nullptr, &device_), "vkCreateDevice");
  try {
    api_.loadDevice(device_);
  } catch (...) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDevice>(api_.vkGetDeviceProcAddr(device_, "vkDestroyDevice"));
    if (destroy) destroy(device_, nullptr);
    throw;
  }
  api_.vkGetDeviceQueue(device_, family_, 0, &queue_);
  if (shaderObjects) loadShaderObjects(physical.handle);
}

void Device::loadShaderObjects(VkPhysicalDevice physical) {
  ShaderObjects so;
  auto load = [&](auto& fn, const char* name) {
    fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(api_.vkGetDeviceProcAddr(device_, name));
    return fn != nullptr;
  };
  if (!load(so.vkCreateShadersEXT, "vkCreateShadersEXT") || !load(so.vkDestroyShaderEXT, "vkDestroyShaderEXT") ||
      !load(so.vkGetShaderBinaryDataEXT, "vkGetShaderBinaryDataEXT") || !load(so.vkCmdBindShadersEXT, "vkCmdBindShadersEXT"))
    return;   // pipelines then, as on a driver without the extension
  auto props = vkStruct<VkPhysicalDeviceShaderObjectPropertiesEXT>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_OBJECT_PROPERTIES_EXT);
  auto props2 = vkStruct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
  props2.pNext = &props;
  api_.vkGetPhysicalDeviceProperties2(physical, &props2);
  std::memcpy(so.binaryUuid, props.shaderBinaryUUID, VK_UUID_SIZE);
  so.binaryVersion = props.shaderBinaryVersion;
  shaderObjects_ = so;
}

Device::Device(const Instance& instance, const PhysicalDevice& physical, VkDevice borrowed, VkQueue queue)
    : api_(instance.api()), info_(physical.info), device_(borrowed), queue_(queue), family_(physical.computeFamily),
      timestampBits_(physical.timestampBits), owned_(false) {
  if (!borrowed || !queue) throw deviceError("Vulkan: adoptDevice needs the application's VkDevice and VkQueue");
  chooseMemory(physical.handle);
  api_.loadDevice(device_);
}

Device::~Device() {
  if (owned_) api_.vkDestroyDevice(device_, nullptr);
}

void Device::chooseMemory(VkPhysicalDevice physical) {
  api_.vkGetPhysicalDeviceProperties(physical, &props_);
  api_.vkGetPhysicalDeviceMemoryProperties(physical, &memory_);
  bool anyDeviceLocal = false;
  // SFFD_VK_STAGING=1 treats the device as discrete even on unified memory, so that the staging
  // path of real GPUs is exercised on lavapipe too.
  unified_ = !envFlag("SFFD_VK_STAGING");
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    VkMemoryPropertyFlags f = memory_.memoryTypes[i].propertyFlags;
    if (!(f & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) || (f & kExcluded)) continue;
    anyDeviceLocal = true;
    if ((f & kMappable) != kMappable) unified_ = false;
  }
  unified_ = unified_ && anyDeviceLocal;
}

// Best memory type for a use among the buffer's allowed types: it must have the required flags;
// each preferred flag present scores 4, each avoided flag present costs 1.
uint32_t Device::memoryType(uint32_t allowedTypes, MemoryUse use) const {
  VkMemoryPropertyFlags required = kMappable, preferred = 0, avoided = 0;
  switch (use) {
    case MemoryUse::Storage:
      required = 0;
      preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
      if (unified_)
        preferred |= kMappable;   // mapped directly: no staging copies
      else
        avoided = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;   // plain VRAM; keeps the small BAR window free
      break;
    case MemoryUse::Upload:
      avoided = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
      break;
    case MemoryUse::Download:
      preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;   // the host reads it: uncached reads are slow
      avoided = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
      break;
    case MemoryUse::Params:
      preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
      break;
  }
  int best = -1, bestScore = 0;
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    VkMemoryPropertyFlags f = memory_.memoryTypes[i].propertyFlags;
    if (!(allowedTypes & (1u << i)) || (f & kExcluded) || (f & required) != required) continue;
    int score = 4 * std::popcount(f & preferred) - std::popcount(f & avoided);
    if (best < 0 || score > bestScore) best = int(i), bestScore = score;
  }
  if (best < 0) throw deviceError("Vulkan: the device has no memory type suitable for sffd's buffers.");
  return uint32_t(best);
}

Allocation Device::allocate(uint64_t bytes, VkBufferUsageFlags usage, MemoryUse use) {
  Allocation a;
  a.size = bytes;
  auto bi = vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  bi.size = bytes > 0 ? bytes : 4;   // Vulkan forbids empty buffers
  bi.usage = usage;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(api_.vkCreateBuffer(device_, &bi, nullptr, &a.buffer), "vkCreateBuffer");
  try {
    VkMemoryRequirements req;
    api_.vkGetBufferMemoryRequirements(device_, a.buffer, &req);
    uint32_t type = memoryType(req.memoryTypeBits, use);
    auto ai = vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = type;
    VkResult r = api_.vkAllocateMemory(device_, &ai, nullptr, &a.memory);
    if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
      throw deviceError("Vulkan: out of memory allocating a buffer of " + std::to_string(bytes) + " bytes.");
    check(r, "vkAllocateMemory");
    gAllocations.fetch_add(1, std::memory_order_relaxed);
    check(api_.vkBindBufferMemory(device_, a.buffer, a.memory, 0), "vkBindBufferMemory");
    bool mappable = (memory_.memoryTypes[type].propertyFlags & kMappable) == kMappable;
    if (mappable && (use != MemoryUse::Storage || unified_))
    {
      check(api_.vkMapMemory(device_, a.memory, 0, VK_WHOLE_SIZE, 0, &a.mapped), "vkMapMemory");
      // On a CPU device (lavapipe, SwiftShader) device memory is the driver's host memory: huge pages asked
      // for before anything touches it (core/huge_pages.h), then whether it is there at all (after the
      // advice, so that the probe's read maps the huge zero page, not a small page in a huge page's place).
      if (info_.type == "cpu") {
        adviseHugePages(a.mapped, bytes);
        if (!mappedMemoryIsThere(a.mapped, req.size)) throw unbackedMemoryError(bytes);
      }
    }
  } catch (...) {
    release(a);
    throw;
  }
  return a;
}

void Device::release(Allocation& a) {
  if (a.buffer) api_.vkDestroyBuffer(device_, a.buffer, nullptr);
  if (a.memory) api_.vkFreeMemory(device_, a.memory, nullptr);   // implicitly unmaps
  a = Allocation{};
}

}  // namespace sffd::vk
