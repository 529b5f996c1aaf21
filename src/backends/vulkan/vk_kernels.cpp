#include "backends/vulkan/vk_kernels.h"

#include <system_error>

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
  // The compileAhead thread finishes the pipeline it is creating, then stops; what it created and
  // nobody used goes with the rest.
  if (thread_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
      queue_.clear();
    }
    changed_.notify_all();
    thread_.join();
  }
  for (auto& [key, a] : ahead_)
    if (a.done && a.pipeline) api.vkDestroyPipeline(dev, a.pipeline, nullptr);
  ahead_.clear();
  for (auto& [key, pipeline] : pipelines_) api.vkDestroyPipeline(dev, pipeline, nullptr);
  pipelines_.clear();
  if (cache_) api.vkDestroyPipelineCache(dev, cache_, nullptr);
  if (pipelineLayout_) api.vkDestroyPipelineLayout(dev, pipelineLayout_, nullptr);
  if (setLayout_) api.vkDestroyDescriptorSetLayout(dev, setLayout_, nullptr);
  cache_ = VK_NULL_HANDLE;
  pipelineLayout_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
}

Kernels::Key Kernels::keyOf(std::string_view kernel, KernelVariant variant) {
  return {std::string(kernel), variantKey(variant)};
}

const EmbeddedKernel& Kernels::checked(std::string_view kernel, KernelVariant variant) const {
  const int v = variantIndex(variant);
  const EmbeddedKernel* k = findKernel(kernel);
  if (!k) throw Error(ErrorKind::Internal, "unknown kernel '" + std::string(kernel) + "'");
  if (variant.f64 && !device_.info().limits.float64)
    throw deviceError("The Vulkan device " + device_.info().name +
                      " has no 64-bit floating point in shaders (shaderFloat64); double precision needs another device.");
  if (!k->spirv[v] || k->spirvWords[v] == 0)
    throw Error(ErrorKind::Internal, "kernel '" + std::string(kernel) + "' has no SPIR-V for variant " + std::to_string(v));
  return *k;
}

VkPipeline Kernels::pipeline(std::string_view kernel, KernelVariant variant) {
  Key key = keyOf(kernel, variant);
  if (auto it = pipelines_.find(key); it != pipelines_.end()) return it->second;
  std::unique_lock<std::mutex> lock(mutex_);
  auto it = ahead_.find(key);
  VkPipeline pipeline = VK_NULL_HANDLE;
  if (it != ahead_.end() && it->second.started) {
    changed_.wait(lock, [&] { return it->second.done; });
    Ahead done = std::move(it->second);
    ahead_.erase(it);
    lock.unlock();
    if (done.error) std::rethrow_exception(done.error);
    pipeline = done.pipeline;
  } else {
    if (it != ahead_.end()) ahead_.erase(it);   // not begun: created here rather than waited for
    lock.unlock();
    pipeline = create(checked(kernel, variant), variant);
  }
  pipelines_.emplace(std::move(key), pipeline);
  return pipeline;
}

void Kernels::compileAhead(std::string_view kernel, KernelVariant variant) {
  Key key = keyOf(kernel, variant);
  if (pipelines_.count(key)) return;
  const EmbeddedKernel* k = nullptr;
  try {
    k = &checked(kernel, variant);
  } catch (const Error&) {
    return;   // the dispatch reports it
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (ahead_.count(key)) return;
  if (!thread_.joinable()) {
    try {
      thread_ = std::thread([this] { createAhead(); });
    } catch (const std::system_error&) {
      return;   // no thread to spare: the pipeline is created at its first dispatch
    }
  }
  Ahead& a = ahead_[key];
  a.kernel = k;
  a.variant = variant;
  queue_.push_back(std::move(key));
  changed_.notify_all();
}

void Kernels::createAhead() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (stopping_) return;
    Key key = std::move(queue_.front());
    queue_.pop_front();
    auto it = ahead_.find(key);
    if (it == ahead_.end() || it->second.started) continue;   // taken over by pipeline()
    Ahead& a = it->second;   // stays put: only pipeline() erases a started entry, after it is done
    a.started = true;
    lock.unlock();
    VkPipeline pipeline = VK_NULL_HANDLE;
    std::exception_ptr error;
    try {
      pipeline = create(*a.kernel, a.variant);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    a.pipeline = pipeline;
    a.error = error;
    a.done = true;
    changed_.notify_all();
  }
}

// Creates the variant's pipeline. Called on the backend's thread or on compileAhead's: it reads only
// what the constructor set up, and Vulkan synchronizes pipeline caches internally.
VkPipeline Kernels::create(const EmbeddedKernel& k, KernelVariant variant) const {
  const int v = variantIndex(variant);
  const Api& api = device_.api();
  VkDevice dev = device_.handle();
  CompileTrace trace("vulkan", k.name, variant);
  auto mi = vkStruct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
  mi.codeSize = k.spirvWords[v] * sizeof(uint32_t);
  mi.pCode = k.spirv[v];
  VkShaderModule module = VK_NULL_HANDLE;
  check(api.vkCreateShaderModule(dev, &mi, nullptr, &module), "vkCreateShaderModule");

  auto ci = vkStruct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
  ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module;
  ci.stage.pName = "main";
  // The assumptions as a specialization constant (ignored by kernels that do not declare it).
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
