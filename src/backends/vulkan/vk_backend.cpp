// sffd::Backend on Vulkan: the buffer table, dispatch recording and host transfers. The pieces
// it stands on: vk_instance (loader, validation, device list), vk_device (queue, memory),
// vk_kernels (pipelines), vk_recorder (command buffer and per-submission resources).
#include "backends/vulkan/vk_backend.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <iterator>
#include <utility>

#include <sffd/error.h>
#include "kernels/common/shader_layout.h"
#include "backends/vulkan/vk_device.h"
#include "backends/vulkan/vk_instance.h"
#include "backends/vulkan/vk_interop.h"
#include "backends/vulkan/vk_kernels.h"
#include "backends/vulkan/vk_recorder.h"

namespace sffd::vk {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// The first usable device (best type first), or the first whose name contains `substring`.
PhysicalDevice selectDevice(const Instance& instance, const std::string& substring) {
  std::vector<PhysicalDevice> devices = instance.physicalDevices();
  std::string names, reasons;
  for (const PhysicalDevice& d : devices) {
    names += (names.empty() ? "" : ", ") + d.info.name;
    if (!d.unusable.empty()) reasons += (reasons.empty() ? "" : "; ") + d.info.name + ": " + d.unusable;
  }
  for (const PhysicalDevice& d : devices) {
    if (!substring.empty() && lower(d.info.name).find(lower(substring)) == std::string::npos) continue;
    if (d.unusable.empty()) return d;
    if (!substring.empty()) throw deviceError("The Vulkan device " + d.info.name + " cannot run sffd: " + d.unusable + ".");
  }
  if (!substring.empty())
    throw deviceError("No Vulkan device name contains '" + substring + "'; devices found: " + names + ".");
  throw deviceError("No Vulkan device can run sffd (" + reasons + ").");
}

// The application's physical device as sffd sees it through the borrowed queue family: float64
// only where the application enabled it, timestamps of that family.
PhysicalDevice adoptedPhysical(const Instance& instance, const vulkan::DeviceConfig& c) {
  if (!c.physicalDevice) throw deviceError("Vulkan: adoptDevice needs the application's VkPhysicalDevice");
  const Api& api = instance.api();
  PhysicalDevice pd = instance.describe(c.physicalDevice);
  uint32_t count = 0;
  api.vkGetPhysicalDeviceQueueFamilyProperties(c.physicalDevice, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  api.vkGetPhysicalDeviceQueueFamilyProperties(c.physicalDevice, &count, families.data());
  if (c.queueFamily >= count || !(families[c.queueFamily].queueFlags & VK_QUEUE_COMPUTE_BIT))
    throw deviceError("Vulkan: queue family " + std::to_string(c.queueFamily) + " of " + pd.info.name +
                      " has no compute (adoptDevice needs VK_QUEUE_COMPUTE_BIT)");
  if (!pd.unusable.empty() && pd.computeFamily != UINT32_MAX)
    throw deviceError("The Vulkan device " + pd.info.name + " cannot run sffd: " + pd.unusable + ".");
  VkPhysicalDeviceProperties props;
  api.vkGetPhysicalDeviceProperties(c.physicalDevice, &props);
  pd.computeFamily = c.queueFamily;
  pd.timestampBits = families[c.queueFamily].timestampValidBits;
  pd.unusable.clear();
  pd.info.provider = "adopted";
  pd.info.limits.float64 = pd.info.limits.float64 && c.shaderFloat64Enabled;
  pd.info.limits.timestamps =
      props.limits.timestampComputeAndGraphics && props.limits.timestampPeriod > 0 && pd.timestampBits > 0;
  return pd;
}

// Stages and accesses of everything sffd records: kernels and copies.
constexpr VkPipelineStageFlags kWorkStages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
constexpr VkAccessFlags kWorkWrites = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
constexpr VkAccessFlags kWorkAccess =
    VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;

class VulkanBackend final : public Backend {
 public:
  explicit VulkanBackend(const Options& options) : VulkanBackend(options, shaderCacheFolder(options.shaderCache)) {}

  VulkanBackend(const Options& options, std::optional<std::filesystem::path> shaderCache)
      : instance_(validationRequested(options.validation)),
        // VK_EXT_shader_object came with the 1.3.246 headers.
        device_(instance_, selectDevice(instance_, options.deviceSubstring),
                shaderCache.has_value() && instance_.validationKnows(VK_MAKE_API_VERSION(0, 1, 3, 246))),
        kernels_(device_, shaderCache ? std::optional<ShaderBinaryCache>(*shaderCache) : std::nullopt),
        recorder_(device_, kernels_.setLayout()),
        info_(device_.info()) {
    if (kernels_.usesShaderObjects()) info_.shaderCache = shaderCache->string();
  }

  explicit VulkanBackend(const vulkan::DeviceConfig& c)
      : instance_(c.instance, c.getInstanceProcAddr),
        device_(instance_, adoptedPhysical(instance_, c), c.device, c.queue),
        kernels_(device_),
        recorder_(device_, kernels_.setLayout()),
        info_(device_.info()) {}

  ~VulkanBackend() override {
    // A device that timed out and still has not finished: nothing it may still use is freed.
    if (!recorder_.settled()) {
      recorder_.abandon();
      device_.abandon();
      return;
    }
    // Submissions are waited for, so nothing should be in flight (unless a wait failed);
    // unsubmitted work is dropped with the command pool. A borrowed device's other queues are the
    // application's: only our queue is waited for.
    if (device_.owned())
      device_.api().vkDeviceWaitIdle(device_.handle());
    else
      device_.api().vkQueueWaitIdle(device_.queue());
    for (Buffer& b : buffers_) device_.release(b.memory);
    device_.release(downloadStaging_);
  }

  const DeviceInfo& info() const override { return info_; }

  BufferId createBuffer(uint64_t bytes) override {
    Allocation a = device_.allocate(
        bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
        MemoryUse::Storage);
    BufferId id;
    if (!freeIds_.empty()) {
      id = freeIds_.back();
      freeIds_.pop_back();
    } else {
      buffers_.emplace_back();
      id = BufferId(buffers_.size());   // ids start at 1: 0 is never a valid buffer
    }
    buffers_[id - 1] = Buffer{a, true, false};
    return id;
  }

  void destroyBuffer(BufferId id) override {
    Buffer& b = lookup(id);
    if (b.pending || recorder_.hung())
      recorder_.releaseAfterSubmit(b.memory);   // recorded, or still running, work refers to it
    else
      device_.release(b.memory);
    b = Buffer{};
    freeIds_.push_back(id);
  }

  void upload(BufferId id, uint64_t offset, const void* data, uint64_t bytes) override {
    Buffer& b = lookup(id);
    checkRange(b, offset, bytes, "upload");
    if (bytes == 0) return;
    if (b.memory.mapped) {
      // Recorded but unsubmitted work may still read the old contents: run it first.
      if (b.pending) finish();
      std::memcpy(static_cast<char*>(b.memory.mapped) + offset, data, bytes);
      return;
    }
    // Staged through the recorder's ring: the copy is recorded in order with the dispatches around it.
    const Recorder::RingRange staging = recorder_.staging(data, bytes);
    recorder_.memoryBarrier(kWorkStages, kWorkWrites, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    VkBufferCopy region{staging.offset, offset, bytes};
    device_.api().vkCmdCopyBuffer(recorder_.commands(), staging.buffer, b.memory.buffer, 1, &region);
    recorder_.memoryBarrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, kWorkStages, kWorkAccess);
    b.pending = true;
  }

  void download(BufferId id, uint64_t offset, void* data, uint64_t bytes) override {
    Buffer& b = lookup(id);
    checkRange(b, offset, bytes, "download");
    if (b.memory.mapped) {
      finish();
      std::memcpy(data, static_cast<const char*>(b.memory.mapped) + offset, bytes);
      return;
    }
    if (bytes == 0) return finish();
    // Staged: copy into host-visible memory behind all recorded work, submit, read it. The staging
    // memory grows, at least doubling, to the largest download. After a timed-out wait a copy may
    // still run into it: it is then freed only once the device settles (freeing memory under a
    // running GPU crashed NVIDIA's driver).
    if (downloadStaging_.size < bytes) {
      const uint64_t size = std::max(bytes, 2 * downloadStaging_.size);
      if (recorder_.hung()) recorder_.releaseAfterSubmit(downloadStaging_);
      else device_.release(downloadStaging_);
      downloadStaging_ = Allocation{};
      downloadStaging_ = device_.allocate(size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::Download);
    }
    recorder_.memoryBarrier(kWorkStages, kWorkWrites, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferCopy region{offset, 0, bytes};
    device_.api().vkCmdCopyBuffer(recorder_.commands(), b.memory.buffer, downloadStaging_.buffer, 1, &region);
    finish();
    std::memcpy(data, downloadStaging_.mapped, bytes);
  }

  void precompile(const std::vector<KernelUse>& kernels) override {
    kernels_.precompile(kernels);
  }

  void dispatch(const Dispatch& d) override {
    const Kernel kernel = kernels_.kernel(d.kernel, d.variant);   // throws before anything is recorded
    const DeviceLimits& limits = device_.info().limits;
    for (int i = 0; i < 3; ++i)
      if (d.groups[i] > limits.maxWorkGroupCount[i])
        throw Error(ErrorKind::Internal, "dispatch of " + std::string(d.kernel) + ": " + std::to_string(d.groups[i]) +
                                             " work groups exceed the device limit (use gridFor)");

    VkDescriptorBufferInfo infos[1 + SFFD_MAX_STORAGE_BINDINGS];
    VkWriteDescriptorSet writes[1 + SFFD_MAX_STORAGE_BINDINGS];
    uint32_t count = 0;
    auto write = [&](uint32_t binding, VkDescriptorType type, VkBuffer buffer, VkDeviceSize offset, VkDeviceSize range) {
      infos[count] = {buffer, offset, range};
      writes[count] = vkStruct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
      writes[count].dstBinding = binding;
      writes[count].descriptorCount = 1;
      writes[count].descriptorType = type;
      writes[count].pBufferInfo = &infos[count];
      ++count;
    };
    if (d.buffers.size() > SFFD_MAX_STORAGE_BINDINGS)
      throw Error(ErrorKind::Internal, "dispatch of " + std::string(d.kernel) + " binds too many buffers");
    for (const BufferBinding& bb : d.buffers) {
      if (bb.slot < 1 || bb.slot > SFFD_MAX_STORAGE_BINDINGS)
        throw Error(ErrorKind::Internal, "dispatch of " + std::string(d.kernel) + ": binding slot " +
                                             std::to_string(bb.slot) + " is not a storage binding");
      Buffer& b = lookup(bb.buffer);
      uint64_t range = storageRange(b, bb, d.kernel);
      write(bb.slot, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, b.memory.buffer, bb.offset, range);
    }
    // Everything that may throw is done: from here on the dispatch is recorded.
    for (const BufferBinding& bb : d.buffers) lookup(bb.buffer).pending = true;
    if (d.params && d.paramsSize > 0) {
      Recorder::RingRange p = recorder_.params(d.params, d.paramsSize);
      write(SFFD_BINDING_PARAMS, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, p.buffer, p.offset, d.paramsSize);
    }
    VkDescriptorSet set = recorder_.descriptorSet();
    for (uint32_t i = 0; i < count; ++i) writes[i].dstSet = set;

    const Api& api = device_.api();
    api.vkUpdateDescriptorSets(device_.handle(), count, writes, 0, nullptr);
    VkCommandBuffer cmd = recorder_.commands();
    kernels_.bind(cmd, kernel);
    api.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, kernels_.pipelineLayout(), 0, 1, &set, 0, nullptr);
    recorder_.beginDispatch(std::string(d.label.empty() ? d.kernel : d.label));
    api.vkCmdDispatch(cmd, d.groups[0], d.groups[1], d.groups[2]);
    recorder_.endDispatch();
  }

  void barrier() override {
    // With nothing recorded, all earlier work has completed and is visible already.
    if (!recorder_.active()) return;
    recorder_.memoryBarrier(kWorkStages, kWorkWrites, kWorkStages, kWorkAccess);
  }

  void finish() override {
    std::vector<DispatchTiming> done = recorder_.submitAndWait();
    timings_.insert(timings_.end(), std::make_move_iterator(done.begin()), std::make_move_iterator(done.end()));
    for (Buffer& b : buffers_) b.pending = false;
  }

  std::vector<DispatchTiming> takeTimings() override { return std::exchange(timings_, {}); }

  VkBuffer vkBuffer(BufferId id) const {
    return id == 0 || id > buffers_.size() || !buffers_[id - 1].live ? VK_NULL_HANDLE : buffers_[id - 1].memory.buffer;
  }

 private:
  struct Buffer {
    Allocation memory;
    bool live = false;
    bool pending = false;   // used by work recorded since the last submission
  };

  Buffer& lookup(BufferId id) {
    if (id == 0 || id > buffers_.size() || !buffers_[id - 1].live)
      throw Error(ErrorKind::Internal, "Vulkan backend: invalid buffer id " + std::to_string(id));
    return buffers_[id - 1];
  }

  static void checkRange(const Buffer& b, uint64_t offset, uint64_t bytes, const char* what) {
    if (offset > b.memory.size || bytes > b.memory.size - offset)
      throw Error(ErrorKind::Internal, std::string(what) + " of " + std::to_string(bytes) + " bytes at offset " +
                                           std::to_string(offset) + " overruns a buffer of " +
                                           std::to_string(b.memory.size) + " bytes");
  }

  // The byte range a storage binding covers; size 0 means to the end of the buffer, capped at the
  // device's binding limit (callers that need more process the data in chunks).
  uint64_t storageRange(const Buffer& b, const BufferBinding& bb, std::string_view kernel) const {
    const DeviceLimits& limits = device_.info().limits;
    std::string where = "dispatch of " + std::string(kernel) + ", slot " + std::to_string(bb.slot) + ": ";
    if (bb.offset % limits.storageOffsetAlignment != 0)
      throw Error(ErrorKind::Internal, where + "offset " + std::to_string(bb.offset) + " is not a multiple of " +
                                           std::to_string(limits.storageOffsetAlignment));
    if (bb.offset >= b.memory.size) throw Error(ErrorKind::Internal, where + "offset is past the end of the buffer");
    uint64_t range = bb.size ? bb.size : std::min(b.memory.size - bb.offset, limits.maxStorageBufferRange);
    if (range > b.memory.size - bb.offset) throw Error(ErrorKind::Internal, where + "range overruns the buffer");
    if (range > limits.maxStorageBufferRange)
      throw Error(ErrorKind::Internal, where + std::to_string(range) + " bytes exceed the device's storage binding limit");
    return range;
  }

  Instance instance_;
  Device device_;
  Kernels kernels_;
  Recorder recorder_;
  DeviceInfo info_;   // the device's, with the shader cache in use
  std::vector<Buffer> buffers_;   // index id - 1
  std::vector<BufferId> freeIds_;
  std::vector<DispatchTiming> timings_;
  // The staging memory downloads read through, kept from one to the next: a discrete GPU's driver pins
  // host memory at each allocation (the streamed 1 M mesh downloads 3 times a chunk, 70 chunks).
  Allocation downloadStaging_;
};

}  // namespace

std::vector<DeviceInfo> listDevices() {
  Instance instance(validationRequested(false));
  std::vector<DeviceInfo> infos;
  for (const PhysicalDevice& d : instance.physicalDevices()) infos.push_back(d.info);
  return infos;
}

std::unique_ptr<Backend> createBackend(const Options& options) { return std::make_unique<VulkanBackend>(options); }

std::unique_ptr<Backend> adoptBackend(const vulkan::DeviceConfig& config) { return std::make_unique<VulkanBackend>(config); }

VkBuffer vkBufferOf(const Backend& backend, BufferId buffer) {
  const auto* vk = dynamic_cast<const VulkanBackend*>(&backend);
  return vk ? vk->vkBuffer(buffer) : VK_NULL_HANDLE;
}

}  // namespace sffd::vk
