// vulkan_embed: an application that owns its Vulkan instance and device lends them to sffd,
// deforms a torus in strict mode, copies the result out of sffd's VkBuffer with a command buffer
// of its own, and checks the bits against the same deformation on the CPU device. Exit 0: identical.
#include <vulkan/vulkan.h>   // before <sffd/vulkan.h>

#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <sffd/sffd.h>
#include <sffd/vulkan.h>

#include "../common/torus.h"

#define VK_CHECK(call) \
  if (VkResult r_ = (call); r_ != VK_SUCCESS) throw std::runtime_error(#call " failed: " + std::to_string(r_))

// The application's side: the system loader's first device and a compute queue.
struct App {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;

  App() {
    VkApplicationInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    ai.apiVersion = VK_API_VERSION_1_1;   // sffd needs 1.1
    VkInstanceCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ci.pApplicationInfo = &ai;
    VK_CHECK(vkCreateInstance(&ci, nullptr, &instance));
    uint32_t n = 1;
    if (vkEnumeratePhysicalDevices(instance, &n, &physical) < 0 || n == 0) throw std::runtime_error("no Vulkan device");
    uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, families.data());
    while (family < count && !(families[family].queueFlags & VK_QUEUE_COMPUTE_BIT)) ++family;
    float priority = 1;
    VkDeviceQueueCreateInfo qi{};
    qi.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qi.queueFamilyIndex = family;
    qi.queueCount = 1;
    qi.pQueuePriorities = &priority;
    VkDeviceCreateInfo di{};
    di.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &qi;
    VK_CHECK(vkCreateDevice(physical, &di, nullptr, &device));
    vkGetDeviceQueue(device, family, 0, &queue);
  }
  ~App() {
    vkDestroyDevice(device, nullptr);   // after every sffd object that used it
    vkDestroyInstance(instance, nullptr);
  }

  // Copies a range of a buffer into host memory: staging buffer, copy command, fence.
  std::vector<unsigned char> read(const sffd::vulkan::BufferRange& range) {
    VkBufferCreateInfo bi{};
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = range.size;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer staging;
    VK_CHECK(vkCreateBuffer(device, &bi, nullptr, &staging));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, staging, &req);
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(physical, &mp);
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkMemoryAllocateInfo mi{};
    mi.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mi.allocationSize = req.size;
    while (!((req.memoryTypeBits >> mi.memoryTypeIndex) & 1) ||
           (mp.memoryTypes[mi.memoryTypeIndex].propertyFlags & want) != want)
      ++mi.memoryTypeIndex;
    VkDeviceMemory memory;
    VK_CHECK(vkAllocateMemory(device, &mi, nullptr, &memory));
    VK_CHECK(vkBindBufferMemory(device, staging, memory, 0));

    VkCommandPoolCreateInfo pi{};

    pi.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pi.queueFamilyIndex = family;
    VkCommandPool pool;
    VK_CHECK(vkCreateCommandPool(device, &pi, nullptr, &pool));
    VkCommandBufferAllocateInfo ca{};
    ca.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ca.commandPool = pool;
    ca.commandBufferCount = 1;
    VkCommandBuffer cmd;
    VK_CHECK(vkAllocateCommandBuffers(device, &ca, &cmd));
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
    // sffd's writes are already visible to later commands on this queue (<sffd/vulkan.h>).
    VkBufferCopy region{range.offset, 0, range.size};
    vkCmdCopyBuffer(cmd, range.buffer, staging, 1, &region);
    VkMemoryBarrier toHost{};
    toHost.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0, nullptr, 0,
                         nullptr);
    VK_CHECK(vkEndCommandBuffer(cmd));
    VkFenceCreateInfo fi{};
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VkFence fence;
    VK_CHECK(vkCreateFence(device, &fi, nullptr, &fence));
    VkSubmitInfo si{};
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    VK_CHECK(vkQueueSubmit(queue, 1, &si, fence));
    VK_CHECK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));

    std::vector<unsigned char> bytes(range.size);
    void* mapped;
    VK_CHECK(vkMapMemory(device, memory, 0, range.size, 0, &mapped));
    std::memcpy(bytes.data(), mapped, range.size);
    vkUnmapMemory(device, memory);
    vkDestroyFence(device, fence, nullptr);
    vkDestroyCommandPool(device, pool, nullptr);
    vkDestroyBuffer(device, staging, nullptr);
    vkFreeMemory(device, memory, nullptr);
    return bytes;
  }
};

int main() try {
  App app;
  sffd::Mesh mesh = example::torus();
  sffd::Lattice lattice = sffd::fitLattice(mesh);
  sffd::applyLatticePreset(lattice, "twist", 0.5);
  size_t bad = 0;
  {
    // The application's device, borrowed: sffd never destroys it. shaderFloat64 was not enabled above.
    sffd::Device gpu = sffd::vulkan::adoptDevice(
        {app.instance, app.physical, app.device, app.family, app.queue, vkGetInstanceProcAddr, false});
    sffd::Device cpu = sffd::Device::open({.name = "cpu"});
    std::printf("vulkan_embed: %s (%s) against %s\n", gpu.label().c_str(), gpu.info().name.c_str(), cpu.label().c_str());

    // Classic FFD, float, strict: the device output maps vertex for vertex onto the result.
    const sffd::DeformOptions classic{.method = sffd::Method::Classic, .strict = true, .precision = sffd::Precision::Float};
    sffd::Deformer onGpu(gpu, mesh, lattice, classic), onCpu(cpu, mesh, lattice, classic);
    onGpu.deform(lattice);
    onCpu.deform(lattice);
    sffd::Mesh expected = onCpu.result();
    for (const sffd::OutputChunk& chunk : onGpu.deviceOutput())
      bad += example::compareClassicChunk(chunk, app.read(sffd::vulkan::bufferOf(onGpu, chunk)), expected);

    // Smooth FFD, strict: the whole result, downloaded by sffd, bit for bit.
    const sffd::DeformOptions smooth{.tess = 3, .strict = true};
    sffd::Deformer smoothGpu(gpu, mesh, lattice, smooth), smoothCpu(cpu, mesh, lattice, smooth);
    smoothGpu.deform(lattice);
    smoothCpu.deform(lattice);
    sffd::Mesh a = smoothGpu.result(), b = smoothCpu.result();
    if (a.positions != b.positions || a.normals != b.normals || a.triangles != b.triangles) ++bad;
    std::printf("vulkan_embed: %zu vertices read from sffd's VkBuffers, %zu smooth triangles; %zu differences\n",
                mesh.positions.size(), a.triangles.size(), bad);
  }   // sffd's objects go first; the application's device after
  return bad == 0 ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "vulkan_embed: %s\n", e.what());
  return 2;
}
