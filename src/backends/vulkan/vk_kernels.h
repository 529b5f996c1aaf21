// Compute pipelines of the embedded kernels. Every kernel shares one descriptor set layout
// (binding 0: the parameter block as a uniform buffer; 1..SFFD_MAX_STORAGE_BINDINGS: storage
// buffers, see kernels/common/layout.h), so one pipeline layout serves all of them. A pipeline is
// built on first use of a (kernel, variant) pair from the SPIR-V embedded at build time.
#pragma once
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
  VkPipeline pipeline(std::string_view kernel, KernelVariant variant);

 private:
  void destroy();

  Device& device_;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
  VkPipelineCache cache_ = VK_NULL_HANDLE;   // in memory only: Mesa and vendor drivers keep their own disk caches
  std::map<std::pair<std::string, uint64_t>, VkPipeline> pipelines_;
};

}  // namespace sffd::vk
