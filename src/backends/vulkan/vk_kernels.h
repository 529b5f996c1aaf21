// Compute pipelines of the embedded kernels. Every kernel shares one descriptor set layout
// (binding 0: the parameter block as a uniform buffer; 1..SFFD_MAX_STORAGE_BINDINGS: storage
// buffers, see kernels/common/layout.h), so one pipeline layout serves all of them. A pipeline is
// built from the SPIR-V embedded at build time, on first use of a (kernel, variant) pair or ahead of
// it (precompile): creating one costs lavapipe tens of milliseconds of SPIR-V to NIR translation and
// optimisation, which other cores can do while the caller works. Builds ahead are taken by one worker a
// core: the first in the order they were asked for, so that the first kernel a job dispatches is ready
// first, the others the largest module left, whose translation is the longest (the last kernel of a job
// is the largest, and waiting for it to be started last made it the run's long pole).
#pragma once
#include <deque>
#include <future>
#include <map>
#include <mutex>
#include <vector>
#include <string>
#include <string_view>
#include <utility>

#include "core/backend.h"
#include "backends/vulkan/vk_device.h"

namespace sffd::vk {

class Kernels {
 public:
  explicit Kernels(Device& device);
  ~Kernels();
  Kernels(const Kernels&) = delete;
  Kernels& operator=(const Kernels&) = delete;

  VkDescriptorSetLayout setLayout() const { return setLayout_; }
  VkPipelineLayout pipelineLayout() const { return pipelineLayout_; }
  // Throws an internal Error for an unknown kernel, a device Error for an f64 variant on a device
  // without shaderFloat64.
  // Waits for the pipeline's build where precompile started one (and rethrows its error).
  VkPipeline pipeline(std::string_view kernel, KernelVariant variant);
  // Queues the pipelines for building on other threads, in this order, unless built or queued already.
  void precompile(const std::vector<KernelUse>& kernels);

 private:
  using Key = std::pair<std::string, uint64_t>;
  Key keyOf(std::string_view kernel, KernelVariant& variant) const;
  VkPipeline build(const std::string& kernel, KernelVariant variant) const;
  // A worker: builds queued pipelines until none is left, in order or the largest module first.
  void buildQueued(bool inOrder);
  // A build no worker has taken yet (or none could start) is made by the caller, now.
  void buildIfQueued(const Key& key);
  void destroy();

  struct QueuedBuild {
    std::string kernel;
    KernelVariant variant;
    size_t spirvWords = 0;   // what the translation's time grows with
    std::promise<VkPipeline> done;
  };

  Device& device_;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
  VkPipelineCache cache_ = VK_NULL_HANDLE;   // in memory only: Mesa and vendor drivers keep their own disk caches
  std::map<Key, VkPipeline> pipelines_;
  std::map<Key, std::future<VkPipeline>> building_;   // queued or built ahead, not yet asked for
  std::mutex queueMutex_;
  std::deque<QueuedBuild> queue_;                        // not yet taken by a worker
  std::vector<std::future<void>> workers_;
};

}  // namespace sffd::vk
