#include "backends/cpu/cpu_backend.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include <sffd/error.h>
#include "core/environment_check.h"
#include "core/huge_pages.h"
#include "core/kernel_registry.h"
#include "core/wall_clock.h"

namespace sffd {

unsigned cpuThreadCount() {
  if (const uint64_t t = integerVariable("SFFD_CPU_THREADS", 1, 256)) return unsigned(t);
  return std::min(std::max(1u, std::thread::hardware_concurrency()), 256u);
}

void checkCpuThreadsVariable() { checkVariableIsInteger("SFFD_CPU_THREADS", 1, 256); }

void checkCpuAvx2Variable() { checkVariableIsOneOf("SFFD_CPU_AVX2", {"0", "1"}); }

bool cpuUsesAvx2() {
#ifdef SFFD_CPU_AVX2_COPIES
  static const bool has = __builtin_cpu_supports("avx2");
  const char* env = std::getenv("SFFD_CPU_AVX2");
  return has && !(env && std::string_view(env) == "0");
#else
  return false;
#endif
}

namespace cpu {

DeviceInfo deviceInfo() {
  DeviceInfo info;
  info.api = "cpu";
  info.provider = "cpu";
  info.name = "CPU reference (" + std::to_string(cpuThreadCount()) + " threads" + (cpuUsesAvx2() ? ", AVX2)" : ")");
  info.driver = "sffd host kernels";
  info.type = "cpu";
  // The largest range a Vulkan device can report: jobs are not chunked below 4 GiB a buffer, and every
  // element index of a binding fits the kernels' 32-bit arithmetic.
  info.limits.maxStorageBufferRange = UINT32_MAX;
  info.limits.storageOffsetAlignment = 16;
  info.limits.float64 = true;
  info.limits.timestamps = true;
  return info;
}

namespace {

// Threads kept for the backend's dispatches. The calling thread works too and returns as soon as every
// block is done: a worker the scheduler has not woken yet (cores shared with other processes) is not
// waited for, it finds no work when it runs.
class ThreadPool {
 public:
  ~ThreadPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      quit_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

  // Runs threads [0, threads) of one grid layer in blocks of whole groups on up to `workers` threads;
  // the first error is rethrown.
  void run(const Kernel& k, const CpuKernelArgs& args, uint64_t threads, unsigned workers) {
    const uint64_t groups = (threads + SFFD_LOCAL_SIZE - 1) / SFFD_LOCAL_SIZE;
    workers = unsigned(std::min<uint64_t>(workers, groups));
    if (workers <= 1) return k.run(args, 0, threads);
    // Several blocks a worker, taken in turn: uneven work (clip patterns) stays balanced.
    Job job(k, args, threads, std::max<uint64_t>(1, groups / (8 * uint64_t(workers))) * SFFD_LOCAL_SIZE);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // A new thread takes part from this job on: it starts from the generation before it.
      while (threads_.size() + 1 < workers) threads_.emplace_back([this, seen = generation_] { serve(seen); });
      job_ = &job;
      seats_ = workers - 1;
      ++generation_;
    }
    wake_.notify_all();
    job.work();
    {
      std::unique_lock<std::mutex> lock(mutex_);
      job_ = nullptr;
      done_.wait(lock, [&] { return active_ == 0; });
    }
    if (job.error) std::rethrow_exception(job.error);
  }

 private:
  struct Job {
    Job(const Kernel& k, const CpuKernelArgs& a, uint64_t t, uint64_t b) : kernel(k), args(a), threads(t), block(b) {}
    const Kernel& kernel;
    const CpuKernelArgs& args;
    uint64_t threads, block;
    std::atomic<uint64_t> next{0};
    std::atomic<bool> failed{false};
    std::mutex errorMutex;
    std::exception_ptr error;

    void work() {
      try {
        for (uint64_t first; !failed && (first = next.fetch_add(block)) < threads;)
          kernel.run(args, first, std::min(first + block, threads));
      } catch (...) {
        std::lock_guard<std::mutex> lock(errorMutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };

  void serve(uint64_t seen) {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return quit_ || (job_ && seats_ > 0 && generation_ != seen); });
      if (quit_) return;
      seen = generation_;
      Job* job = job_;
      --seats_;
      ++active_;
      lock.unlock();
      job->work();
      lock.lock();
      if (--active_ == 0) done_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> threads_;
  Job* job_ = nullptr;
  unsigned seats_ = 0, active_ = 0;
  uint64_t generation_ = 0;
  bool quit_ = false;
};

class CpuBackend final : public Backend {
 public:
  CpuBackend() : info_(deviceInfo()) {}

  const DeviceInfo& info() const override { return info_; }

  BufferId createBuffer(uint64_t bytes) override {
    BufferId id = nextId_++;
    buffers_[id] = {std::make_unique_for_overwrite<std::byte[]>(bytes), bytes};   // uninitialised, as on a GPU
    adviseHugePages(buffers_[id].data.get(), bytes);   // untouched yet: the kernels' first writes fault once per 2 MiB
    return id;
  }

  void destroyBuffer(BufferId id) override { buffers_.erase(id); }

  void upload(BufferId id, uint64_t offset, const void* data, uint64_t bytes) override {
    Buf& b = buffer(id, offset, bytes, "upload");
    if (bytes) std::memcpy(b.data.get() + offset, data, bytes);
  }

  void download(BufferId id, uint64_t offset, void* data, uint64_t bytes) override {
    Buf& b = buffer(id, offset, bytes, "download");
    if (bytes) std::memcpy(data, b.data.get() + offset, bytes);
  }

  void dispatch(const Dispatch& d) override {
    const Kernel* kernel = findKernel(d.kernel);
    if (!kernel) throw Error(ErrorKind::Internal, "cpu: no kernel named '" + std::string(d.kernel) + "'");
    const std::string what = std::string(d.kernel) + " (" + variantName(d.variant) + ")";
    const DeviceLimits& L = info_.limits;
    for (int i = 0; i < 3; ++i)
      if (d.groups[i] > L.maxWorkGroupCount[i])
        throw Error(ErrorKind::Internal, "cpu: dispatch of " + what + " has " + std::to_string(d.groups[i]) + " groups on axis " +
                                             std::to_string(i) + ", the device allows " + std::to_string(L.maxWorkGroupCount[i]) +
                                             " (use gridFor)");
    if (d.paramsSize < kernel->paramsSize || (d.paramsSize && !d.params))
      throw Error(ErrorKind::Internal, "cpu: " + what + " takes a " + std::to_string(kernel->paramsSize) +
                                           "-byte parameter block, the dispatch gives " + std::to_string(d.params ? d.paramsSize : 0));
    // The block at 16-byte alignment, as the kernels' structs need.
    params_.assign((d.paramsSize + 15) / 16, gpu::Vec4{});
    if (d.paramsSize) std::memcpy(params_.data(), d.params, d.paramsSize);

    CpuKernelArgs args;
    args.kernel = d.kernel;
    args.variant = d.variant;
    args.params = params_.data();
    for (const BufferBinding& bb : d.buffers) {
      const std::string slot = "slot " + std::to_string(bb.slot);
      if (bb.slot < 1 || bb.slot > SFFD_MAX_STORAGE_BINDINGS)
        throw Error(ErrorKind::Internal, "cpu: " + what + ": storage binding " + slot + " is outside 1.." +
                                             std::to_string(SFFD_MAX_STORAGE_BINDINGS));
      auto it = buffers_.find(bb.buffer);
      if (it == buffers_.end()) throw Error(ErrorKind::Internal, "cpu: " + what + ": " + slot + " names no buffer");
      Buf& b = it->second;
      if (bb.offset % L.storageOffsetAlignment != 0)
        throw Error(ErrorKind::Internal, "cpu: " + what + ": " + slot + " offset " + std::to_string(bb.offset) +
                                             " is not a multiple of " + std::to_string(L.storageOffsetAlignment));
      if (bb.offset > b.size || (bb.size > 0 && bb.size > b.size - bb.offset))
        throw Error(ErrorKind::Internal, "cpu: " + what + ": " + slot + " range runs past the end of its buffer");
      const uint64_t size = bb.size > 0 ? bb.size : b.size - bb.offset;
      if (size == 0) throw Error(ErrorKind::Internal, "cpu: " + what + ": " + slot + " binds no bytes");
      if (size > L.maxStorageBufferRange)
        throw Error(ErrorKind::Internal, "cpu: " + what + ": " + slot + " binds " + std::to_string(size) +
                                             " bytes, the device allows " + std::to_string(L.maxStorageBufferRange) +
                                             " (process in chunks)");
      args.slots[bb.slot] = {b.data.get() + bb.offset, size};
    }

    auto t0 = std::chrono::steady_clock::now();
    // sffdThreadIndex() ignores the z axis: each layer of the grid runs the same thread indices.
    const uint64_t threads = uint64_t(d.groups[0]) * SFFD_LOCAL_SIZE * d.groups[1];
    for (uint32_t z = 0; z < d.groups[2] && threads > 0; ++z) pool_.run(*kernel, args, threads, cpuThreadCount());
    timings_.push_back({std::string(d.label.empty() ? d.kernel : d.label), msSince(t0)});
  }

  // Every dispatch has run and written its buffers before dispatch() returned.
  void barrier() override {}
  void finish() override {}

  std::vector<DispatchTiming> takeTimings() override { return std::exchange(timings_, {}); }

 private:
  struct Buf {
    std::unique_ptr<std::byte[]> data;
    uint64_t size = 0;
  };

  Buf& buffer(BufferId id, uint64_t offset, uint64_t bytes, const char* what) {
    auto it = buffers_.find(id);
    if (it == buffers_.end()) throw Error(ErrorKind::Internal, std::string("cpu: ") + what + " of an unknown buffer");
    if (offset > it->second.size || bytes > it->second.size - offset)
      throw Error(ErrorKind::Internal, std::string("cpu: ") + what + " of " + std::to_string(bytes) + " bytes at " +
                                           std::to_string(offset) + " runs past the end of a " + std::to_string(it->second.size) +
                                           "-byte buffer");
    return it->second;
  }

  DeviceInfo info_;
  std::unordered_map<BufferId, Buf> buffers_;
  BufferId nextId_ = 1;
  std::vector<gpu::Vec4> params_;
  std::vector<DispatchTiming> timings_;
  ThreadPool pool_;
};

}  // namespace

std::unique_ptr<Backend> createBackend() { return std::make_unique<CpuBackend>(); }

}  // namespace cpu
}  // namespace sffd
