#include "backends/vulkan/vk_kernels.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <system_error>
#include <thread>

#include <sffd/error.h>
#include "core/kernel_registry.h"
#include "kernels/common/shader_layout.h"

namespace sffd::vk {

Kernels::Kernels(Device& device) : device_(device) {
  const Api& api = device_.api();
  VkDevice dev = device_.handle();

  VkDescriptorSetLayoutBinding bindings[1 + SFFD_MAX_STORAGE_BINDINGS] = {};
  for (uint32_t i = 0; i <= SFFD_MAX_STORAGE_BINDINGS; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType =
        i == SFFD_BINDING_PARAMS ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  auto li = vkStruct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
  li.bindingCount = 1 + SFFD_MAX_STORAGE_BINDINGS;
  li.pBindings = bindings;
  check(api.vkCreateDescriptorSetLayout(dev, &li, nullptr, &setLayout_), "vkCreateDescriptorSetLayout");

  auto pi = vkStruct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
  pi.setLayoutCount = 1;
  pi.pSetLayouts = &setLayout_;
  auto ci = vkStruct<VkPipelineCacheCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO);
  try {
    check(api.vkCreatePipelineLayout(dev, &pi, nullptr, &pipelineLayout_), "vkCreatePipelineLayout");
    check(api.vkCreatePipelineCache(dev, &ci, nullptr, &cache_), "vkCreatePipelineCache");
  } catch (...) {
    destroy();
    throw;
  }
}

Kernels::~Kernels() { destroy(); }

void Kernels::destroy() {
  const Api& api = device_.api();
  VkDevice dev = device_.handle();
  {
    std::lock_guard<std::mutex> lock(queueMutex_);
    queue_.clear();   // their futures report broken promises, caught below
  }
  for (std::future<void>& w : workers_) w.wait();
  workers_.clear();
  for (auto& [key, building] : building_) {
    try {
      pipelines_.emplace(key, building.get());
    } catch (...) {   // a build that failed, or was never made, and was never asked for
    }
  }
  building_.clear();
  for (auto& [key, pipeline] : pipelines_) api.vkDestroyPipeline(dev, pipeline, nullptr);
  pipelines_.clear();
  if (cache_) api.vkDestroyPipelineCache(dev, cache_, nullptr);
  if (pipelineLayout_) api.vkDestroyPipelineLayout(dev, pipelineLayout_, nullptr);
  if (setLayout_) api.vkDestroyDescriptorSetLayout(dev, setLayout_, nullptr);
  cache_ = VK_NULL_HANDLE;
  pipelineLayout_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
}

Kernels::Key Kernels::keyOf(std::string_view kernel, KernelVariant& variant) const {
  variant = forDevice(variant, device_.info());
  return {std::string(kernel), variantKey(variant)};
}

VkPipeline Kernels::pipeline(std::string_view kernel, KernelVariant variant) {
  Key key = keyOf(kernel, variant);
  if (auto it = pipelines_.find(key); it != pipelines_.end()) return it->second;
  VkPipeline pipeline = VK_NULL_HANDLE;
  if (auto it = building_.find(key); it != building_.end()) {
    std::future<VkPipeline> f = std::move(it->second);
    building_.erase(it);
    buildIfQueued(key);
    pipeline = f.get();
  } else {
    pipeline = build(key.first, variant);
  }
  pipelines_.emplace(std::move(key), pipeline);
  return pipeline;
}

void Kernels::precompile(const std::vector<KernelUse>& kernels) {
  size_t queued = 0;
  {
    std::lock_guard<std::mutex> lock(queueMutex_);
    for (const KernelUse& use : kernels) {
      KernelVariant variant = use.variant;
      Key key = keyOf(use.kernel, variant);
      if (pipelines_.count(key) || building_.count(key)) continue;
      const EmbeddedKernel* k = findKernel(use.kernel);
      QueuedBuild b{key.first, variant, k ? spirvFor(*k, variant).size() : 0, {}};
      building_.emplace(std::move(key), b.done.get_future());
      queue_.push_back(std::move(b));
      ++queued;
    }
  }
  // vkCreateComputePipelines may be called from several threads at once (the cache synchronises
  // itself); the workers touch nothing else of this object but the queue.
  const size_t cores = std::max(1u, std::thread::hardware_concurrency());
  std::erase_if(workers_, [](const std::future<void>& w) { return w.wait_for(std::chrono::seconds(0)) == std::future_status::ready; });
  for (size_t i = 0; i < std::min(queued, cores); ++i) {
    try {
      workers_.push_back(std::async(std::launch::async, [this, inOrder = i == 0] { buildQueued(inOrder); }));
    } catch (const std::system_error&) {   // no thread to be had: the workers started, or the caller, build them
      break;
    }
  }
}

void Kernels::buildIfQueued(const Key& key) {
  std::optional<QueuedBuild> mine;
  {
    std::lock_guard<std::mutex> lock(queueMutex_);
    auto it = std::find_if(queue_.begin(), queue_.end(),
                           [&](const QueuedBuild& b) { return b.kernel == key.first && variantKey(b.variant) == key.second; });
    if (it == queue_.end()) return;
    mine = std::move(*it);
    queue_.erase(it);
  }
  try {
    mine->done.set_value(build(mine->kernel, mine->variant));
  } catch (...) {
    mine->done.set_exception(std::current_exception());
  }
}

void Kernels::buildQueued(bool inOrder) {
  for (;;) {
    QueuedBuild b;
    {
      std::lock_guard<std::mutex> lock(queueMutex_);
      if (queue_.empty()) return;
      auto next = inOrder ? queue_.begin()
                          : std::max_element(queue_.begin(), queue_.end(),
                                             [](const QueuedBuild& x, const QueuedBuild& y) { return x.spirvWords < y.spirvWords; });
      b = std::move(*next);
      queue_.erase(next);
    }
    try {
      b.done.set_value(build(b.kernel, b.variant));
    } catch (...) {
      b.done.set_exception(std::current_exception());
    }
  }
}

VkPipeline Kernels::build(const std::string& kernel, KernelVariant variant) const {
  const int v = variantIndex(variant);
  const EmbeddedKernel* k = findKernel(kernel);
  if (!k) throw Error(ErrorKind::Internal, "unknown kernel '" + kernel + "'");
  if (variant.f64 && !device_.info().limits.float64)
    throw deviceError("The Vulkan device " + device_.info().name +
                      " has no 64-bit floating point in shaders (shaderFloat64); double precision needs another device.");
  const std::span<const uint32_t> spirv = spirvFor(*k, variant);
  if (spirv.empty())
    throw Error(ErrorKind::Internal, "kernel '" + kernel + "' has no SPIR-V for variant " + std::to_string(v));
  const Api& api = device_.api();
  VkDevice dev = device_.handle();
  CompileScope compiling("vulkan", kernel, variant);
  auto mi = vkStruct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
  mi.codeSize = spirv.size_bytes();
  mi.pCode = spirv.data();
  VkShaderModule module = VK_NULL_HANDLE;
  check(api.vkCreateShaderModule(dev, &mi, nullptr, &module), "vkCreateShaderModule");

  auto ci = vkStruct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
  ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module;
  ci.stage.pName = "main";
  // The assumptions as a specialization constant (ignored by modules that do not declare it).
  const uint32_t assumptions = variant.assumptions;
  VkSpecializationMapEntry entry{SFFD_SPEC_ASSUMPTIONS, 0, sizeof(assumptions)};
  VkSpecializationInfo spec{1, &entry, sizeof(assumptions), &assumptions};
  ci.stage.pSpecializationInfo = &spec;
  ci.layout = pipelineLayout_;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkResult r = api.vkCreateComputePipelines(dev, cache_, 1, &ci, nullptr, &pipeline);
  api.vkDestroyShaderModule(dev, module, nullptr);   // the pipeline keeps what it needs
  check(r, "vkCreateComputePipelines");
  return pipeline;
}

}  // namespace sffd::vk
