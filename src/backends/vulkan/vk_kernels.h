// Compute pipelines of the embedded kernels. Every kernel shares one descriptor set layout
// (binding 0: the parameter block as a uniform buffer; 1..SFFD_MAX_STORAGE_BINDINGS: storage
// buffers, see kernels/common/layout.h), so one pipeline layout serves all of them. A pipeline is
// built from the SPIR-V embedded at build time, on first use of a (kernel, variant) pair or ahead of
// it on a thread of its own (precompile): creating one costs lavapipe tens of milliseconds of
// SPIR-V to NIR translation and optimisation, which other cores can do while the caller works.
#pragma once
#include <future>
#include <map>
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
  // Starts building the pipeline on another thread unless it is built or being built.
  void precompile(std::string_view kernel, KernelVariant variant);

 private:
  using Key = std::pair<std::string, uint64_t>;
  Key keyOf(std::string_view kernel, KernelVariant& variant) const;
  VkPipeline build(const std::string& kernel, KernelVariant variant) const;
  void destroy();

  Device& device_;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
  VkPipelineCache cache_ = VK_NULL_HANDLE;   // in memory only: Mesa and vendor drivers keep their own disk caches
  std::map<Key, VkPipeline> pipelines_;
  std::map<Key, std::future<VkPipeline>> building_;   // precompiled, not yet asked for
};

}  // namespace sffd::vk
