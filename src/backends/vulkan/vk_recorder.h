// One submission's worth of recorded work and the transient resources it uses: the command buffer,
// descriptor sets, the rings of parameter blocks and of upload staging, timestamp queries and what is freed
// once the work is done. Everything is recycled in one go when the submission completes, so chunked jobs
// may record thousands of dispatches with no per-dispatch fence or allocation. Submissions are synchronous (finish() waits),
// hence one command buffer and one fence suffice.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/backend.h"
#include "backends/vulkan/vk_device.h"

namespace sffd::vk {

class Recorder {
 public:
  Recorder(Device& device, VkDescriptorSetLayout setLayout);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // After a wait that timed out: waits once more (10 s); false when the device is still busy.
  bool settled();
  // Whether the last wait timed out: the device may still be running what was submitted.
  bool hung() const { return hung_; }
  // Forgets every handle without destroying it: what a device still using them needs (a hung driver).
  void abandon();
  // Whether commands were recorded since the last submission.
  bool active() const { return active_; }
  // The command buffer, begun on first use after a submission.
  VkCommandBuffer commands();
  void memoryBarrier(VkPipelineStageFlags srcStages, VkAccessFlags srcAccess, VkPipelineStageFlags dstStages,
                     VkAccessFlags dstAccess);

  // A descriptor set of the shared kernel layout, valid until the submission completes.
  VkDescriptorSet descriptorSet();
  // Where a ring put what it was given.
  struct RingRange {
    VkBuffer buffer;
    VkDeviceSize offset;
  };
  // Copies a parameter block into its ring; returns where to bind it as a uniform buffer.
  RingRange params(const void* data, size_t bytes);
  // Copies an upload's bytes into host-visible staging memory, valid until the submission completes;
  // returns the buffer and offset to copy from.
  RingRange staging(const void* data, uint64_t bytes);

  // Brackets one dispatch: names its timing record and writes its timestamps when the device has them.
  void beginDispatch(std::string label);
  void endDispatch();

  // Frees the allocation once the work recorded so far has completed.
  void releaseAfterSubmit(Allocation allocation);

  // Ends, submits and waits for the recorded work, then recycles everything.
  // Returns the timing of each dispatch in the submission, in order.
  std::vector<DispatchTiming> submitAndWait();

 private:
  void recycle();
  void destroy();

  Device& device_;
  VkDescriptorSetLayout setLayout_;
  VkCommandPool commandPool_ = VK_NULL_HANDLE;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool hung_ = false;   // the last wait timed out
  bool active_ = false;

  std::vector<VkDescriptorPool> descriptorPools_;
  uint32_t setsAllocated_ = 0;   // in this submission, across pools

  // Host-visible memory handed out in order and rewound when a submission completes: its chunks are kept
  // from one submission to the next (a discrete GPU's driver pins host memory at each allocation), up to
  // `keep` bytes in all; larger ones are freed once their submission completes.
  struct Ring {
    VkBufferUsageFlags usage;
    MemoryUse use;
    VkDeviceSize chunkBytes, keep;
    std::vector<Allocation> chunks;
    size_t chunk = 0;          // chunk being filled
    VkDeviceSize offset = 0;   // next free byte in it
  };
  RingRange take(Ring& ring, const void* data, uint64_t bytes, VkDeviceSize align);
  void rewind(Ring& ring);
  Ring params_, staging_;

  bool timestamps_ = false;
  uint64_t timestampMask_ = 0;
  std::vector<VkQueryPool> queryPools_;
  std::vector<std::string> labels_;   // one per dispatch of this submission; 2 queries each

  std::vector<Allocation> releases_;
};

}  // namespace sffd::vk
