#include "backends/vulkan/vk_kernels.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <system_error>
#include <thread>

#include <sffd/error.h>
#include "core/fnv1a.h"
#include "core/kernel_registry.h"
#include "kernels/common/shader_layout.h"

namespace sffd::vk {

Kernels::Kernels(Device& device, std::optional<ShaderBinaryCache> cache) : device_(device) {
  if (device_.shaderObjects()) cache_ = std::move(cache);
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
  setLayoutHash_ = fnv1a64(bindings, sizeof bindings);   // no pointers in them (no immutable samplers)
  check(api.vkCreateDescriptorSetLayout(dev, &li, nullptr, &setLayout_), "vkCreateDescriptorSetLayout");

  auto pi = vkStruct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
  pi.setLayoutCount = 1;
  pi.pSetLayouts = &setLayout_;
  auto ci = vkStruct<VkPipelineCacheCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO);
  try {
    check(api.vkCreatePipelineLayout(dev, &pi, nullptr, &pipelineLayout_), "vkCreatePipelineLayout");
    check(api.vkCreatePipelineCache(dev, &ci, nullptr, &pipelineCache_), "vkCreatePipelineCache");
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
      built_.emplace(key, building.get());
    } catch (...) {   // a build that failed, or was never made, and was never asked for
    }
  }
  building_.clear();
  for (auto& [key, k] : built_) {
    if (k.pipeline) api.vkDestroyPipeline(dev, k.pipeline, nullptr);
    if (k.shader) device_.shaderObjects()->vkDestroyShaderEXT(dev, k.shader, nullptr);
  }
  built_.clear();
  if (pipelineCache_) api.vkDestroyPipelineCache(dev, pipelineCache_, nullptr);
  if (pipelineLayout_) api.vkDestroyPipelineLayout(dev, pipelineLayout_, nullptr);
  if (setLayout_) api.vkDestroyDescriptorSetLayout(dev, setLayout_, nullptr);
  pipelineCache_ = VK_NULL_HANDLE;
  pipelineLayout_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
}

Kernels::Key Kernels::keyOf(std::string_view kernel, KernelVariant& variant) const {
  variant = forDevice(variant, device_.info());
  return {std::string(kernel), variantKey(variant)};
}

Kernel Kernels::kernel(std::string_view name, KernelVariant variant) {
  Key key = keyOf(name, variant);
  if (auto it = built_.find(key); it != built_.end()) return it->second;
  Kernel k;
  if (auto it = building_.find(key); it != building_.end()) {
    std::future<Kernel> f = std::move(it->second);
    building_.erase(it);
    buildIfQueued(key);
    k = f.get();
  } else {
    k = build(key.first, variant);
  }
  built_.emplace(std::move(key), k);
  return k;
}

void Kernels::bind(VkCommandBuffer commands, const Kernel& k) const {
  if (k.shader) {
    const VkShaderStageFlagBits stage = VK_SHADER_STAGE_COMPUTE_BIT;
    device_.shaderObjects()->vkCmdBindShadersEXT(commands, 1, &stage, &k.shader);
  } else {
    device_.api().vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, k.pipeline);
  }
}

void Kernels::precompile(const std::vector<KernelUse>& kernels) {
  size_t queued = 0;
  {
    std::lock_guard<std::mutex> lock(queueMutex_);
    for (const KernelUse& use : kernels) {
      KernelVariant variant = use.variant;
      Key key = keyOf(use.kernel, variant);
      if (built_.count(key) || building_.count(key)) continue;
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

Kernel Kernels::build(const std::string& kernel, KernelVariant variant) const {
  const int v = variantIndex(variant);
  const EmbeddedKernel* k = findKernel(kernel);
  if (!k) throw Error(ErrorKind::Internal, "unknown kernel '" + kernel + "'");
  if (variant.f64 && !device_.info().limits.float64)
    throw deviceError("The Vulkan device " + device_.info().name +
                      " has no 64-bit floating point in shaders (shaderFloat64); double precision needs another device.");
  const std::span<const uint32_t> spirv = spirvFor(*k, variant);
  if (spirv.empty())
    throw Error(ErrorKind::Internal, "kernel '" + kernel + "' has no SPIR-V for variant " + std::to_string(v));
  CompileScope compiling("vulkan", kernel, variant);
  // The assumptions as a specialization constant (ignored by modules that do not declare it).
  const uint32_t assumptions = variant.assumptions;
  VkSpecializationMapEntry entry{SFFD_SPEC_ASSUMPTIONS, 0, sizeof(assumptions)};
  VkSpecializationInfo spec{1, &entry, sizeof(assumptions), &assumptions};
  return cache_ ? buildShader(kernel, variant, spirv, spec, compiling) : buildPipeline(spirv, spec);
}

Kernel Kernels::buildPipeline(std::span<const uint32_t> spirv, const VkSpecializationInfo& spec) const {
  const Api& api = device_.api();
  VkDevice dev = device_.handle();
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
  ci.stage.pSpecializationInfo = &spec;
  ci.layout = pipelineLayout_;
  Kernel k;
  VkResult r = api.vkCreateComputePipelines(dev, pipelineCache_, 1, &ci, nullptr, &k.pipeline);
  api.vkDestroyShaderModule(dev, module, nullptr);   // the pipeline keeps what it needs
  check(r, "vkCreateComputePipelines");
  return k;
}

Kernel Kernels::buildShader(const std::string& kernel, KernelVariant variant, std::span<const uint32_t> spirv,
                            const VkSpecializationInfo& spec, CompileScope& compiling) const {
  const ShaderObjects& so = *device_.shaderObjects();
  VkDevice dev = device_.handle();
  // Everything the driver's binary depends on: the driver's binary format, the kernel's SPIR-V, its
  // specialization (the assumptions, part of the variant's key) and the descriptor set layout it was
  // made for (lavapipe lowers the bindings into the binary; the SPIR-V need not change with it).
  std::string key = "vulkan";
  char hex[3];
  for (uint8_t b : so.binaryUuid) {
    std::snprintf(hex, sizeof hex, "%02x", b);
    key += hex;
  }
  key += " " + std::to_string(so.binaryVersion) + " " + std::to_string(setLayoutHash_) + " " + kernel + " " +
         std::to_string(variantKey(variant)) + " " +
         std::to_string(spirv.size_bytes()) + " " + std::to_string(fnv1a64(spirv.data(), spirv.size_bytes()));

  auto ci = vkStruct<VkShaderCreateInfoEXT>(VK_STRUCTURE_TYPE_SHADER_CREATE_INFO_EXT);
  ci.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.pName = "main";
  ci.setLayoutCount = 1;
  ci.pSetLayouts = &setLayout_;
  ci.pSpecializationInfo = &spec;
  Kernel k;
  if (std::optional<std::vector<uint8_t>> binary = cache_->load(key)) {
    ci.codeType = VK_SHADER_CODE_TYPE_BINARY_EXT;
    ci.codeSize = binary->size();
    ci.pCode = binary->data();
    // Anything but success (the driver's VK_INCOMPATIBLE_SHADER_BINARY_EXT, an error) is a miss.
    if (so.vkCreateShadersEXT(dev, 1, &ci, nullptr, &k.shader) == VK_SUCCESS && k.shader) {
      compiling.note("from the shader cache");
      return k;
    }
    k.shader = VK_NULL_HANDLE;
  }
  ci.codeType = VK_SHADER_CODE_TYPE_SPIRV_EXT;
  ci.codeSize = spirv.size_bytes();
  ci.pCode = spirv.data();
  check(so.vkCreateShadersEXT(dev, 1, &ci, nullptr, &k.shader), "vkCreateShadersEXT");
  size_t bytes = 0;
  if (so.vkGetShaderBinaryDataEXT(dev, k.shader, &bytes, nullptr) == VK_SUCCESS && bytes > 0) {
    std::vector<uint8_t> binary(bytes);
    if (so.vkGetShaderBinaryDataEXT(dev, k.shader, &bytes, binary.data()) == VK_SUCCESS)
      cache_->store(key, std::span(binary.data(), bytes));
  }
  return k;
}

}  // namespace sffd::vk
