// Compute pipelines (or shader objects) of the embedded kernels. Every kernel shares one descriptor set layout
// (binding 0: the parameter block as a uniform buffer; 1..SFFD_MAX_STORAGE_BINDINGS: storage
// buffers, see kernels/common/layout.h), so one pipeline layout serves all of them. A pipeline is
// built from the SPIR-V embedded at build time, on first use of a (kernel, variant) pair or ahead of
// it (precompile): creating one costs lavapipe tens of milliseconds of SPIR-V to NIR translation and
// optimisation, which other cores can do while the caller works. Builds ahead are taken by one worker a
// core: the first in the order they were asked for, so that the first kernel a job dispatches is ready
// first, the others the largest module left, whose translation is the longest (the last kernel of a job
// is the largest, and waiting for it to be started last made it the run's long pole).
// With a shader binary cache, on a device with VK_EXT_shader_object, a kernel is a shader object instead:
// made from the binary the driver gave back in an earlier process where the cache has it (lavapipe then
// skips the translation), from the SPIR-V otherwise, its binary then stored for the next process.
#pragma once
#include <deque>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <vector>
#include <string>
#include <string_view>
#include <utility>

#include "core/backend.h"
#include "core/kernel_registry.h"
#include "core/shader_binary_cache.h"
#include "backends/vulkan/vk_device.h"

namespace sffd::vk {

// One built kernel: a pipeline, or a shader object (the other handle null).
struct Kernel {
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkShaderEXT shader = VK_NULL_HANDLE;
};

class Kernels {
 public:
  // Shader objects are used where `cache` is given and the device enabled them.
  explicit Kernels(Device& device, std::optional<ShaderBinaryCache> cache = std::nullopt);
  ~Kernels();
  Kernels(const Kernels&) = delete;
  Kernels& operator=(const Kernels&) = delete;

  VkDescriptorSetLayout setLayout() const { return setLayout_; }
  VkPipelineLayout pipelineLayout() const { return pipelineLayout_; }
  bool usesShaderObjects() const { return cache_.has_value(); }
  // Throws an internal Error for an unknown kernel, a device Error for an f64 variant on a device
  // without shaderFloat64.
  // Waits for the kernel's build where precompile started one (and rethrows its error).
  Kernel kernel(std::string_view kernel, KernelVariant variant);
  // Records the kernel's binding for the dispatches that follow in `commands`.
  void bind(VkCommandBuffer commands, const Kernel& kernel) const;
  // Queues the pipelines for building on other threads, in this order, unless built or queued already.
  void precompile(const std::vector<KernelUse>& kernels);

 private:
  using Key = std::pair<std::string, uint64_t>;
  Key keyOf(std::string_view kernel, KernelVariant& variant) const;
  Kernel build(const std::string& kernel, KernelVariant variant) const;
  Kernel buildPipeline(std::span<const uint32_t> spirv, const VkSpecializationInfo& spec) const;
  Kernel buildShader(const std::string& kernel, KernelVariant variant, std::span<const uint32_t> spirv,
                     const VkSpecializationInfo& spec, CompileScope& compiling) const;
  // A worker: builds queued pipelines until none is left, in order or the largest module first.
  void buildQueued(bool inOrder);
  // A build no worker has taken yet (or none could start) is made by the caller, now.
  void buildIfQueued(const Key& key);
  void destroy();

  struct QueuedBuild {
    std::string kernel;
    KernelVariant variant;
    size_t spirvWords = 0;   // what the translation's time grows with
    std::promise<Kernel> done;
  };

  Device& device_;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  uint64_t setLayoutHash_ = 0;   // of its bindings: part of a shader binary's key
  VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
  VkPipelineCache pipelineCache_ = VK_NULL_HANDLE;   // in memory only: Mesa and vendor drivers keep their own disk caches
  std::optional<ShaderBinaryCache> cache_;   // shader objects' binaries; none: pipelines
  std::map<Key, Kernel> built_;
  std::map<Key, std::future<Kernel>> building_;   // queued or built ahead, not yet asked for
  std::mutex queueMutex_;
  std::deque<QueuedBuild> queue_;                        // not yet taken by a worker
  std::vector<std::future<void>> workers_;
};

}  // namespace sffd::vk
