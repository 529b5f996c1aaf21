// Measuring tool: how long the first Vulkan device takes to make a compute pipeline of each SPIR-V module
// given (vkCreateComputePipelines, no pipeline cache), the median of REPEAT builds, one at a time on the
// calling thread. On lavapipe that is its SPIR-V to NIR translation and optimisation, which it does again
// in every process (docs/performance/whole_run.md, "Where Mesa 22.3's whole Vulkan run goes"). The layout is the
// kernels' (kernels/common/layout.h); specialization constants keep their defaults.
//   spirv_translate_time REPEAT build/spv/deform_smooth.v0.s0.spv ...
#include <vulkan/vulkan.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

#include "kernels/common/shader_layout.h"

namespace {

[[noreturn]] void fail(const char* what, VkResult r = VK_SUCCESS) {
  std::fprintf(stderr, "spirv_translate_time: error: %s (VkResult %d)\n", what, int(r));
  std::exit(1);
}

template <class T>
T vkStruct(VkStructureType type) {
  T t{};
  t.sType = type;
  return t;
}

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) fail(what, r);
}

std::vector<uint32_t> readWords(const char* path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) fail(path);
  const std::streamoff bytes = in.tellg();
  if (bytes <= 0 || bytes % 4) fail("not a SPIR-V module (size)");
  std::vector<uint32_t> words(size_t(bytes) / 4);
  in.seekg(0);
  in.read(reinterpret_cast<char*>(words.data()), bytes);
  if (words[0] != 0x07230203u) fail("not a SPIR-V module (magic)");
  return words;
}

}  // namespace

int main(int argc, char** argv) {
  const int repeat = argc > 2 ? std::atoi(argv[1]) : 0;
  if (repeat < 1) {
    std::fprintf(stderr, "usage: spirv_translate_time REPEAT MODULE.spv...\n");
    return 2;
  }
  auto app = vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.apiVersion = VK_API_VERSION_1_1;
  auto ii = vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  ii.pApplicationInfo = &app;
  VkInstance instance;
  check(vkCreateInstance(&ii, nullptr, &instance), "vkCreateInstance");
  uint32_t count = 1;
  VkPhysicalDevice physical;
  if (vkEnumeratePhysicalDevices(instance, &count, &physical) < 0 || count == 0) fail("no Vulkan device");
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physical, &props);
  const float priority = 1;
  auto qi = vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  qi.queueCount = 1;
  qi.pQueuePriorities = &priority;
  VkPhysicalDeviceFeatures features;   // the f64 kernels need shaderFloat64
  vkGetPhysicalDeviceFeatures(physical, &features);
  auto di = vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
  di.queueCreateInfoCount = 1;
  di.pQueueCreateInfos = &qi;
  di.pEnabledFeatures = &features;
  VkDevice device;
  check(vkCreateDevice(physical, &di, nullptr, &device), "vkCreateDevice");

  VkDescriptorSetLayoutBinding bindings[1 + SFFD_MAX_STORAGE_BINDINGS] = {};
  for (uint32_t i = 0; i <= SFFD_MAX_STORAGE_BINDINGS; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = i == SFFD_BINDING_PARAMS ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  auto li = vkStruct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
  li.bindingCount = 1 + SFFD_MAX_STORAGE_BINDINGS;
  li.pBindings = bindings;
  VkDescriptorSetLayout setLayout;
  check(vkCreateDescriptorSetLayout(device, &li, nullptr, &setLayout), "vkCreateDescriptorSetLayout");
  auto pli = vkStruct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &setLayout;
  VkPipelineLayout layout;
  check(vkCreatePipelineLayout(device, &pli, nullptr, &layout), "vkCreatePipelineLayout");

  std::printf("# %s, %d builds each\n", props.deviceName, repeat);
  for (int a = 2; a < argc; ++a) {
    const std::vector<uint32_t> words = readWords(argv[a]);
    std::vector<double> ms;
    for (int r = 0; r < repeat; ++r) {
      const auto start = std::chrono::steady_clock::now();
      auto mi = vkStruct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
      mi.codeSize = words.size() * 4;
      mi.pCode = words.data();
      VkShaderModule module;
      check(vkCreateShaderModule(device, &mi, nullptr, &module), "vkCreateShaderModule");
      auto ci = vkStruct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
      ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
      ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
      ci.stage.module = module;
      ci.stage.pName = "main";
      ci.layout = layout;
      VkPipeline pipeline;
      check(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline), argv[a]);
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      vkDestroyPipeline(device, pipeline, nullptr);
      vkDestroyShaderModule(device, module, nullptr);
    }
    std::sort(ms.begin(), ms.end());
    std::printf("%8.2f ms median %8.2f min %7zu bytes  %s\n", ms[ms.size() / 2], ms[0], words.size() * 4, argv[a]);
  }
  vkDestroyPipelineLayout(device, layout, nullptr);
  vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
  vkDestroyDevice(device, nullptr);
  vkDestroyInstance(instance, nullptr);
}
