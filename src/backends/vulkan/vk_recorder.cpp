#include "backends/vulkan/vk_recorder.h"
#include "core/device_timeout.h"

#include <algorithm>
#include <cstring>

#include <sffd/error.h>
#include "kernels/common/shader_layout.h"

namespace sffd::vk {

namespace {

constexpr uint32_t kSetsPerPool = 256;
constexpr VkDeviceSize kParamChunkBytes = 64 << 10;
// Staging: the lattice and the clip offsets of an interactive edit fit the first chunk; a streamed chunk's
// inputs (about 8 MiB beyond the vertices, docs/performance/scaling.md) fit what is kept.
constexpr VkDeviceSize kStagingChunkBytes = 1 << 20;
constexpr VkDeviceSize kStagingKeptBytes = 64 << 20;
constexpr uint32_t kQueriesPerPool = 512;   // 256 dispatches

}  // namespace

Recorder::Recorder(Device& device, VkDescriptorSetLayout setLayout)
    : device_(device),
      setLayout_(setLayout),
      params_{VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, MemoryUse::Params, kParamChunkBytes, ~VkDeviceSize(0), {}},
      staging_{VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUse::Upload, kStagingChunkBytes, kStagingKeptBytes, {}} {
  const Api& api = device_.api();
  VkDevice dev = device_.handle();
  timestamps_ = device_.info().limits.timestamps;
  timestampMask_ = device_.timestampBits() >= 64 ? ~0ull : (1ull << device_.timestampBits()) - 1;
  try {
    auto pi = vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    pi.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    pi.queueFamilyIndex = device_.queueFamily();
    check(api.vkCreateCommandPool(dev, &pi, nullptr, &commandPool_), "vkCreateCommandPool");
    auto ai = vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    ai.commandPool = commandPool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    check(api.vkAllocateCommandBuffers(dev, &ai, &commands_), "vkAllocateCommandBuffers");
    auto fi = vkStruct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    check(api.vkCreateFence(dev, &fi, nullptr, &fence_), "vkCreateFence");
  } catch (...) {
    destroy();
    throw;
  }
}

Recorder::~Recorder() { destroy(); }

bool Recorder::settled() {
  if (!hung_) return true;
  // A grace period of its own (not the timeout, which tests make tiny): a slow device finishes and is
  // cleaned up as usual; a hung one costs 10 s more at exit.
  const VkResult waited = device_.api().vkWaitForFences(device_.handle(), 1, &fence_, VK_TRUE, 10'000'000'000ull);
  hung_ = waited != VK_SUCCESS;
  return !hung_;
}

void Recorder::abandon() {
  releases_.clear();
  params_.chunks.clear();
  staging_.chunks.clear();
  descriptorPools_.clear();
  queryPools_.clear();
  fence_ = VK_NULL_HANDLE;
  commandPool_ = VK_NULL_HANDLE;
}

void Recorder::destroy() {
  const Api& api = device_.api();
  VkDevice dev = device_.handle();
  for (Allocation& a : releases_) device_.release(a);
  for (Ring* ring : {&params_, &staging_})
    for (Allocation& a : ring->chunks) device_.release(a);
  for (VkDescriptorPool p : descriptorPools_) api.vkDestroyDescriptorPool(dev, p, nullptr);
  for (VkQueryPool q : queryPools_) api.vkDestroyQueryPool(dev, q, nullptr);
  if (fence_) api.vkDestroyFence(dev, fence_, nullptr);
  if (commandPool_) api.vkDestroyCommandPool(dev, commandPool_, nullptr);   // frees the command buffer
  abandon();   // forgets the handles just destroyed
}

VkCommandBuffer Recorder::commands() {
  if (!active_) {
    auto bi = vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(device_.api().vkBeginCommandBuffer(commands_, &bi), "vkBeginCommandBuffer");
    active_ = true;
  }
  return commands_;
}

void Recorder::memoryBarrier(VkPipelineStageFlags srcStages, VkAccessFlags srcAccess, VkPipelineStageFlags dstStages,
                             VkAccessFlags dstAccess) {
  auto b = vkStruct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  b.srcAccessMask = srcAccess;
  b.dstAccessMask = dstAccess;
  device_.api().vkCmdPipelineBarrier(commands(), srcStages, dstStages, 0, 1, &b, 0, nullptr, 0, nullptr);
}

// Pools hold kSetsPerPool sets of the one layout; counting sets avoids relying on
// VK_ERROR_OUT_OF_POOL_MEMORY, which drivers may report late or not at all.
VkDescriptorSet Recorder::descriptorSet() {
  const Api& api = device_.api();
  VkDevice dev = device_.handle();
  uint32_t pool = setsAllocated_ / kSetsPerPool;
  if (pool == descriptorPools_.size()) {
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, kSetsPerPool},
                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kSetsPerPool * SFFD_MAX_STORAGE_BINDINGS}};
    auto pi = vkStruct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
    pi.maxSets = kSetsPerPool;
    pi.poolSizeCount = 2;
    pi.pPoolSizes = sizes;
    VkDescriptorPool p = VK_NULL_HANDLE;
    check(api.vkCreateDescriptorPool(dev, &pi, nullptr, &p), "vkCreateDescriptorPool");
    descriptorPools_.push_back(p);
  }
  auto ai = vkStruct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
  ai.descriptorPool = descriptorPools_[pool];
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &setLayout_;
  VkDescriptorSet set = VK_NULL_HANDLE;
  check(api.vkAllocateDescriptorSets(dev, &ai, &set), "vkAllocateDescriptorSets");
  ++setsAllocated_;
  return set;
}

Recorder::RingRange Recorder::params(const void* data, size_t bytes) {
  const VkPhysicalDeviceLimits& limits = device_.properties().limits;
  if (bytes > limits.maxUniformBufferRange)
    throw Error(ErrorKind::Internal, "parameter block of " + std::to_string(bytes) + " bytes exceeds the device's " +
                                         std::to_string(limits.maxUniformBufferRange) + "-byte uniform range");
  return take(params_, data, bytes, std::max<VkDeviceSize>(limits.minUniformBufferOffsetAlignment, 16));
}

Recorder::RingRange Recorder::staging(const void* data, uint64_t bytes) { return take(staging_, data, bytes, 16); }

Recorder::RingRange Recorder::take(Ring& ring, const void* data, uint64_t bytes, VkDeviceSize align) {
  ring.offset = (ring.offset + align - 1) / align * align;
  // Move to the next chunk with room (allocating one when none is left).
  while (ring.chunk < ring.chunks.size() && ring.offset + bytes > ring.chunks[ring.chunk].size) {
    ++ring.chunk;
    ring.offset = 0;
  }
  if (ring.chunk == ring.chunks.size())
    ring.chunks.push_back(device_.allocate(std::max<VkDeviceSize>(ring.chunkBytes, bytes), ring.usage, ring.use));
  Allocation& chunk = ring.chunks[ring.chunk];
  std::memcpy(static_cast<char*>(chunk.mapped) + ring.offset, data, bytes);
  RingRange range{chunk.buffer, ring.offset};
  ring.offset += bytes;
  return range;
}

// The submission that used the ring completed: its chunks are free again, those beyond `keep` freed.
void Recorder::rewind(Ring& ring) {
  ring.chunk = 0;
  ring.offset = 0;
  VkDeviceSize kept = 0;
  size_t n = 0;
  for (Allocation& a : ring.chunks) {
    if (kept + a.size <= ring.keep) kept += a.size, ring.chunks[n++] = a;
    else device_.release(a);
  }
  ring.chunks.resize(n);
}

// The start timestamp waits for earlier compute work, so that each record times its own dispatch.
void Recorder::beginDispatch(std::string label) {
  VkCommandBuffer cmd = commands();
  if (timestamps_) {
    const Api& api = device_.api();
    uint32_t query = uint32_t(labels_.size()) * 2;
    uint32_t pool = query / kQueriesPerPool;
    if (pool == queryPools_.size()) {
      auto qi = vkStruct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
      qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
      qi.queryCount = kQueriesPerPool;
      VkQueryPool q = VK_NULL_HANDLE;
      check(api.vkCreateQueryPool(device_.handle(), &qi, nullptr, &q), "vkCreateQueryPool");
      queryPools_.push_back(q);
    }
    // Queries must be reset before each use: once per pool and submission, at its first use.
    if (query % kQueriesPerPool == 0) api.vkCmdResetQueryPool(cmd, queryPools_[pool], 0, kQueriesPerPool);
    api.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, queryPools_[pool], query % kQueriesPerPool);
  }
  labels_.push_back(std::move(label));
}

void Recorder::endDispatch() {
  if (!timestamps_) return;
  uint32_t query = uint32_t(labels_.size()) * 2 - 1;
  device_.api().vkCmdWriteTimestamp(commands(), VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                    queryPools_[query / kQueriesPerPool], query % kQueriesPerPool);
}

void Recorder::releaseAfterSubmit(Allocation allocation) { releases_.push_back(allocation); }

std::vector<DispatchTiming> Recorder::submitAndWait() {
  std::vector<DispatchTiming> timings;
  if (!active_) return timings;
  const Api& api = device_.api();
  VkDevice dev = device_.handle();

  // Device writes (kernels, copies) become visible to the host reading mapped memory after the wait,
  // and to every later command on the queue (an adopting application's draws and copies).
  memoryBarrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                VK_ACCESS_HOST_READ_BIT | VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
  check(api.vkEndCommandBuffer(commands_), "vkEndCommandBuffer");
  auto si = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  si.commandBufferCount = 1;
  si.pCommandBuffers = &commands_;
  check(api.vkQueueSubmit(device_.queue(), 1, &si, fence_), "vkQueueSubmit");
  // A finite wait: a hung driver is a device error, not a hang (core/device_timeout.h).
  const VkResult waited = api.vkWaitForFences(dev, 1, &fence_, VK_TRUE, deviceTimeoutNs());
  if (waited == VK_TIMEOUT) {
    hung_ = true;
    throw deviceError(deviceTimeoutMessage(device_.info().name));
  }
  check(waited, "vkWaitForFences");

  std::vector<uint64_t> ticks(labels_.size() * 2);
  if (timestamps_) {
    for (size_t first = 0; first < ticks.size(); first += kQueriesPerPool) {
      uint32_t count = uint32_t(std::min<size_t>(kQueriesPerPool, ticks.size() - first));
      check(api.vkGetQueryPoolResults(dev, queryPools_[first / kQueriesPerPool], 0, count, count * sizeof(uint64_t),
                                      ticks.data() + first, sizeof(uint64_t),
                                      VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "vkGetQueryPoolResults");
    }
  }
  const double msPerTick = double(device_.properties().limits.timestampPeriod) * 1e-6;
  for (size_t i = 0; i < labels_.size(); ++i) {
    double ms = -1;
    if (timestamps_) ms = double((ticks[2 * i + 1] - ticks[2 * i]) & timestampMask_) * msPerTick;
    timings.push_back({std::move(labels_[i]), ms});
  }
  recycle();
  return timings;
}

// Everything the finished submission used becomes free again.
void Recorder::recycle() {
  const Api& api = device_.api();
  VkDevice dev = device_.handle();
  check(api.vkResetFences(dev, 1, &fence_), "vkResetFences");
  check(api.vkResetCommandPool(dev, commandPool_, 0), "vkResetCommandPool");
  uint32_t poolsUsed = (setsAllocated_ + kSetsPerPool - 1) / kSetsPerPool;
  for (uint32_t i = 0; i < poolsUsed; ++i) check(api.vkResetDescriptorPool(dev, descriptorPools_[i], 0), "vkResetDescriptorPool");
  setsAllocated_ = 0;
  rewind(params_);
  rewind(staging_);
  labels_.clear();
  for (Allocation& a : releases_) device_.release(a);
  releases_.clear();
  active_ = false;
}

}  // namespace sffd::vk
