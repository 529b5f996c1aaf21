// Compute pipelines of the embedded kernels. Every kernel shares one descriptor set layout
// (binding 0: the parameter block as a uniform buffer; 1..SFFD_MAX_STORAGE_BINDINGS: storage
// buffers, see kernels/common/layout.h), so one pipeline layout serves all of them. A pipeline is
// built on first use of a (kernel, variant) pair from the SPIR-V embedded at build time, or ahead of
// it on a thread of its own (compileAhead).
#pragma once
#include <condition_variable>
#include <deque>
#include <exception>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <string_view>
#include <utility>

#include "core/backend.h"
#include "core/kernel_registry.h"
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
  // Queues the pipeline for creation on a thread of the backend's, one at a time in the order asked
  // (the host has few cores: the first needed come first); pipeline() takes it over, or creates it
  // itself when the thread has not begun it. On lavapipe (Mesa 22.3, whose pipeline cache keeps
  // nothing) creating deform_smooth's pipeline translates and optimizes its SPIR-V anew each run, a
  // few hundred ms that the host's preparation of the mesh can hide.
  void compileAhead(std::string_view kernel, KernelVariant variant);

 private:
  using Key = std::pair<std::string, uint64_t>;
  static Key keyOf(std::string_view kernel, KernelVariant variant);
  // Checks that the device can run the variant; throws as pipeline() documents.
  const EmbeddedKernel& checked(std::string_view kernel, KernelVariant variant) const;
  VkPipeline create(const EmbeddedKernel& k, KernelVariant variant) const;
  void createAhead();   // the compileAhead thread
  void destroy();

  Device& device_;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
  VkPipelineCache cache_ = VK_NULL_HANDLE;   // in memory only: Mesa and vendor drivers keep their own disk caches
  std::map<Key, VkPipeline> pipelines_;

  // compileAhead's queue and results, under mutex_; pipelines_ is the backend thread's alone.
  struct Ahead {
    const EmbeddedKernel* kernel = nullptr;
    KernelVariant variant;
    bool started = false, done = false;
    VkPipeline pipeline = VK_NULL_HANDLE;
    std::exception_ptr error;
  };
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<Key, Ahead> ahead_;
  std::deque<Key> queue_;   // keys of ahead_ not started (a key pipeline() took over is skipped)
  bool stopping_ = false;
  std::thread thread_;

};

}  // namespace sffd::vk
