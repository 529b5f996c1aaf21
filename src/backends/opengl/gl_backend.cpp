// OpenGL 4.3+ core and OpenGL ES 3.1 compute driver (sffd::Backend) on a context from gl_context.h.
// The two APIs share this code; where they differ (no doubles, glGetBufferSubData, glBufferStorage or
// core timestamps in ES; storage bindings from 0; the ES 3.1 minimum limits) it asks ctx_->es().
// Every GL call goes through glad, whose entry points the context loads when it becomes current;
// each public method activates the backend's context first, so backends of several providers can
// live in one process, and restores the bindings it changes (gl_state.h), so that an application's
// context can be shared (adopted contexts). The public API ends each of its calls with endCall(),
// which lets sffd's own EGL or OSMesa context go, so that the next call may come from another thread.
#include "backends/opengl/gl_backend.h"

#include <glad/gl.h>

#include <algorithm>
#include <chrono>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <unordered_map>
#include <utility>

#include <sffd/error.h>
#include "backends/opengl/gl_check.h"
#include "backends/opengl/gl_es_limits.h"
#include "backends/opengl/gl_programs.h"
#include "backends/opengl/gl_state.h"
#include "core/device_timeout.h"
#include "core/environment_check.h"
#include "core/kernel_registry.h"
#include "core/wall_clock.h"
#include "kernels/common/shader_layout.h"

namespace sffd::gl {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string glString(GLenum which) {
  const GLubyte* s = glGetString(which);
  return s ? reinterpret_cast<const char*>(s) : "";
}

uint64_t alignUp(uint64_t v, uint64_t a) { return a <= 1 ? v : (v + a - 1) / a * a; }

class GlBackend final : public Backend {
 public:
  GlBackend(std::shared_ptr<Context> context, bool deviceLimits) : ctx_(std::move(context)) {
    ctx_->activate();
    es_ = ctx_->es();
    heldToEsMinimum_ = es_ && !deviceLimits;
    // As many compiler threads as the driver likes (NVIDIA's, Mesa's radeonsi and iris use them); an
    // adopted context keeps the count its application set (the hint is the context's state).
    const bool parallelCompile = !es_ && (GLAD_GL_KHR_parallel_shader_compile || GLAD_GL_ARB_parallel_shader_compile);
    if (parallelCompile && !ctx_->adopted()) {
      if (GLAD_GL_KHR_parallel_shader_compile)
        glMaxShaderCompilerThreadsKHR(0xffffffffu);
      else
        glMaxShaderCompilerThreadsARB(0xffffffffu);
    }
    GLint major = 0, minor = 0, profile = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (!es_) glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    info_.api = es_ ? "gles" : "gl";
    info_.provider = ctx_->name();
    info_.name = glString(GL_RENDERER);
    info_.driver = glString(GL_VERSION);
    // "4.5 (Core Profile) Mesa 22.3.6": the driver's own version where it names one.
    size_t mesa = info_.driver.find("Mesa ");
    info_.driverVersion = mesa == std::string::npos ? info_.driver : info_.driver.substr(mesa);
    if (es_ && major * 10 + minor < 31)
      throw deviceError("gles/" + info_.provider + ": compute needs OpenGL ES 3.1, the context is " +
                        std::to_string(major) + "." + std::to_string(minor) + " (" + info_.driver + ", " + info_.name + ")");
    if (!es_ && (major * 10 + minor < 43 || !(profile & GL_CONTEXT_CORE_PROFILE_BIT)))
      throw deviceError("gl/" + info_.provider + ": compute needs OpenGL 4.3 core, the context is " +
                        std::to_string(major) + "." + std::to_string(minor) +
                        ((profile & GL_CONTEXT_CORE_PROFILE_BIT) ? " core" : " (not core)") + " (" + info_.driver +
                        ", " + info_.name + ")");
    std::string r = lower(info_.name);
    bool cpu = r.find("llvmpipe") != std::string::npos || r.find("softpipe") != std::string::npos ||
               r.find("swrast") != std::string::npos;
    info_.type = cpu ? "cpu" : "other";

    DeviceLimits& L = info_.limits;
    GLint64 ssboSize = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &ssboSize);
    L.maxStorageBufferRange = static_cast<uint64_t>(ssboSize);
    GLint align = 0;
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &align);
    L.storageOffsetAlignment = static_cast<uint64_t>(std::max(align, 1));
    for (GLuint i = 0; i < 3; ++i) {
      GLint n = 0;
      glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, i, &n);
      L.maxWorkGroupCount[i] = static_cast<uint32_t>(std::max(n, 0));
    }
    // GL 4.0+ core has doubles (ARB_gpu_shader_fp64); ES has none. NVIDIA's GL compiler does too, but
    // keeps a kernel's indexed local arrays of doubles in 32-bit registers (`TEMP lmem0[]` in its
    // program binary), so every double that passes through one is rounded to float: 1e-9 to 2e-5 off
    // the CPU on the H200 (driver 580), where the same kernels through Vulkan give the CPU's bits
    // (docs/CONFORMANCE.md "NVIDIA's OpenGL doubles"). Refused there rather than wrong.
    L.float64 = !es_ && !doublesLoseBits(glString(GL_VENDOR));
    GLint bits = 0;
    // ES: timestamps only through EXT_disjoint_timer_query (gl_loader_es.cpp points glQueryCounter at it).
    if (!es_ || glad_glQueryCounter) glGetQueryiv(GL_TIMESTAMP, GL_QUERY_COUNTER_BITS, &bits);
    // OSMesa's llvmpipe runs a dispatch at the next flush, after both timestamps (70 ns apart around a 3 ms
    // deform): its dispatches are timed on the host instead, as the CPU device's are.
    hostTimed_ = info_.provider == "osmesa";
    L.timestamps = bits > 0 || hostTimed_;

    GLint uboAlign = 0, maxBlock = 0;
    glGetIntegerv(GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT, &uboAlign);
    glGetIntegerv(GL_MAX_UNIFORM_BLOCK_SIZE, &maxBlock);
    uboAlign_ = static_cast<uint64_t>(std::max(uboAlign, 16));
    maxParams_ = static_cast<uint64_t>(std::max(maxBlock, 16384));
    if (heldToEsMinimum_) {
      L.maxStorageBufferRange = std::min(L.maxStorageBufferRange, es31::kMaxStorageBlockSize);
      for (uint32_t& n : L.maxWorkGroupCount) n = std::min(n, es31::kMaxGroupCount);
      maxParams_ = es31::kMaxUniformBlockSize;
    }
    uboSize_ = std::max<uint64_t>(kRingBytes, alignUp(maxParams_, uboAlign_));
    StateGuard state;
    state.buffer(GL_UNIFORM_BUFFER);
    glGenBuffers(1, &ubo_);
    glBindBuffer(GL_UNIFORM_BUFFER, ubo_);
    glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(uboSize_), nullptr, GL_STREAM_DRAW);
    checkGl("creating the parameter ring");
    programs_ = std::make_unique<Programs>(info_, ctx_->glVersion(), es_, heldToEsMinimum_, parallelCompile);
  }

  ~GlBackend() override {
    if (hung_) return;   // the device may still use everything: leave it to the context's end
    try {
      activate();
      glFinish();
      programs_->release();
      for (auto& [id, b] : buffers_) glDeleteBuffers(1, &b.name);
      for (const Pending& p : pending_)
        if (p.begin) {
          glDeleteQueries(1, &p.begin);
          glDeleteQueries(1, &p.end);
        }
      if (!freeQueries_.empty()) glDeleteQueries(static_cast<GLsizei>(freeQueries_.size()), freeQueries_.data());
      glDeleteBuffers(1, &ubo_);
      glFinish();
    } catch (...) {
      // the context could not be made current: its destruction frees everything anyway
    }
  }

  const DeviceInfo& info() const override { return info_; }
  const ProgramResources& resources(std::string_view kernelName, KernelVariant variant) {
    activate();
    const EmbeddedKernel* kernel = findKernel(kernelName);
    if (!kernel) throw Error(ErrorKind::Internal, "gl: no kernel named '" + std::string(kernelName) + "'");
    return programs_->get(*kernel, variant).resources;
  }
  GLuint bufferObject(BufferId id) const {
    auto it = buffers_.find(id);
    return it == buffers_.end() ? 0 : it->second.name;
  }

  BufferId createBuffer(uint64_t bytes) override {
    activate();
    StateGuard state;
    state.buffer(GL_COPY_WRITE_BUFFER);
    GLuint name = 0;
    glGenBuffers(1, &name);
    glBindBuffer(GL_COPY_WRITE_BUFFER, name);
    // Zero-sized storage is an error in GL: keep 16 bytes behind an empty buffer.
    GLsizeiptr size = static_cast<GLsizeiptr>(std::max<uint64_t>(bytes, 16));
    if (!es_ && GLAD_GL_VERSION_4_4)
      glBufferStorage(GL_COPY_WRITE_BUFFER, size, nullptr, GL_DYNAMIC_STORAGE_BIT);
    else
      glBufferData(GL_COPY_WRITE_BUFFER, size, nullptr, GL_DYNAMIC_DRAW);
    try {
      checkGl("createBuffer");
    } catch (...) {
      glDeleteBuffers(1, &name);
      throw;
    }
    BufferId id = nextId_++;
    buffers_[id] = {name, bytes};
    return id;
  }

  // Called by destructors, so it never throws: where the context cannot be made current on this thread
  // (another thread is inside a call on the device), the buffer is deleted at the next call that can.
  void destroyBuffer(BufferId id) override {
    auto it = buffers_.find(id);
    if (it == buffers_.end()) return;
    const GLuint name = it->second.name;
    buffers_.erase(it);
    try {
      activate();
    } catch (const Error&) {
      orphans_.push_back(name);
      return;
    }
    glDeleteBuffers(1, &name);
  }

  void endCall() noexcept override { ctx_->endCall(); }

  void upload(BufferId id, uint64_t offset, const void* data, uint64_t bytes) override {
    activate();
    const Buf& b = buffer(id, offset, bytes, "upload");
    if (bytes == 0) return;
    // Shader writes are incoherent: order them before this write.
    if (dirty_) glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    StateGuard state;
    state.buffer(GL_COPY_WRITE_BUFFER);
    glBindBuffer(GL_COPY_WRITE_BUFFER, b.name);
    glBufferSubData(GL_COPY_WRITE_BUFFER, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
    checkGl("upload");
  }

  void download(BufferId id, uint64_t offset, void* data, uint64_t bytes) override {
    activate();
    const Buf& b = buffer(id, offset, bytes, "download");
    if (bytes == 0) return;
    if (dirty_) {
      glMemoryBarrier(kAllBarriers);
      dirty_ = false;
    }
    StateGuard state;
    state.buffer(GL_COPY_READ_BUFFER);
    glBindBuffer(GL_COPY_READ_BUFFER, b.name);
    waitIdle("download");   // bounded: glGetBufferSubData alone would wait forever on a hung driver
    if (es_) {
      // ES has no glGetBufferSubData: map the range for reading.
      void* mapped = glMapBufferRange(GL_COPY_READ_BUFFER, static_cast<GLintptr>(offset),
                                      static_cast<GLsizeiptr>(bytes), GL_MAP_READ_BIT);
      if (mapped) std::memcpy(data, mapped, bytes);
      if (mapped && !glUnmapBuffer(GL_COPY_READ_BUFFER)) throw deviceError("gles: a downloaded buffer was lost (glUnmapBuffer)");
    } else {
      glGetBufferSubData(GL_COPY_READ_BUFFER, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
    }
    checkGl("download");
  }

  // NVIDIA's GL otherwise compiles a job's kernels one after the other: 148 s for strict double
  // (docs/performance/gpu.md, run 4).
  void precompile(const std::vector<KernelUse>& kernels) override {
    activate();
    programs_->precompile(kernels);
  }

  void dispatch(const Dispatch& d) override {
    activate();
    programs_->settle();
    const EmbeddedKernel* kernel = findKernel(d.kernel);
    if (!kernel) throw Error(ErrorKind::Internal, "gl: no kernel named '" + std::string(d.kernel) + "'");
    const Program& prog = programs_->get(*kernel, d.variant);
    std::string what = std::string(d.kernel) + " (" + variantName(d.variant) + ")";

    const DeviceLimits& L = info_.limits;
    for (int i = 0; i < 3; ++i)
      if (d.groups[i] > L.maxWorkGroupCount[i])
        throw Error(ErrorKind::Internal, "gl: dispatch of " + what + " has " + std::to_string(d.groups[i]) +
                                             " groups on axis " + std::to_string(i) + ", the device allows " +
                                             std::to_string(L.maxWorkGroupCount[i]) + " (use gridFor)");

    // Parameter block: next slot of the ring, orphaned when it wraps.
    if (prog.paramsBlockSize >= 0 && d.paramsSize < static_cast<uint64_t>(prog.paramsBlockSize))
      throw Error(ErrorKind::Internal, "gl: " + what + " takes a " + std::to_string(prog.paramsBlockSize) +
                                           "-byte parameter block, the dispatch gives " +
                                           std::to_string(d.paramsSize));
    if (d.paramsSize > maxParams_)
      throw Error(ErrorKind::Internal, "gl: parameter block of " + what + " is larger than GL_MAX_UNIFORM_BLOCK_SIZE");
    uint64_t span = alignUp(std::max<uint64_t>(d.paramsSize, 16), 16);
    StateGuard state;
    state.program();
    state.indexed(GL_UNIFORM_BUFFER, SFFD_BINDING_PARAMS);
    for (const BufferBinding& bb : d.buffers)
      if (bb.slot >= 1 && bb.slot <= SFFD_MAX_STORAGE_BINDINGS) state.indexed(GL_SHADER_STORAGE_BUFFER, storageIndex(bb.slot));
    glBindBuffer(GL_UNIFORM_BUFFER, ubo_);
    if (uboHead_ + span > uboSize_) {
      glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(uboSize_), nullptr, GL_STREAM_DRAW);
      uboHead_ = 0;
    }
    if (d.params && d.paramsSize > 0)
      glBufferSubData(GL_UNIFORM_BUFFER, static_cast<GLintptr>(uboHead_), static_cast<GLsizeiptr>(d.paramsSize),
                      d.params);
    glBindBufferRange(GL_UNIFORM_BUFFER, SFFD_BINDING_PARAMS, ubo_, static_cast<GLintptr>(uboHead_),
                      static_cast<GLsizeiptr>(span));
    uboHead_ = alignUp(uboHead_ + span, uboAlign_);

    for (const BufferBinding& bb : d.buffers) {
      if (bb.slot < 1 || bb.slot > SFFD_MAX_STORAGE_BINDINGS)
        throw Error(ErrorKind::Internal, "gl: " + what + ": storage binding slot " + std::to_string(bb.slot) +
                                             " is outside 1.." + std::to_string(SFFD_MAX_STORAGE_BINDINGS));
      auto it = buffers_.find(bb.buffer);
      if (it == buffers_.end())
        throw Error(ErrorKind::Internal, "gl: " + what + ": slot " + std::to_string(bb.slot) + " names no buffer");
      const Buf& b = it->second;
      if (bb.offset % L.storageOffsetAlignment != 0)
        throw Error(ErrorKind::Internal, "gl: " + what + ": slot " + std::to_string(bb.slot) + " offset " +
                                             std::to_string(bb.offset) + " is not a multiple of " +
                                             std::to_string(L.storageOffsetAlignment));
      if (bb.offset > b.size || (bb.size > 0 && bb.size > b.size - bb.offset))
        throw Error(ErrorKind::Internal, "gl: " + what + ": slot " + std::to_string(bb.slot) +
                                             " range runs past the end of its buffer");
      uint64_t size = bb.size > 0 ? bb.size : b.size - bb.offset;
      if (size == 0)
        throw Error(ErrorKind::Internal, "gl: " + what + ": slot " + std::to_string(bb.slot) + " binds no bytes");
      if (size > L.maxStorageBufferRange)
        throw Error(ErrorKind::Internal, "gl: " + what + ": slot " + std::to_string(bb.slot) + " binds " +
                                             std::to_string(size) + " bytes, the device allows " +
                                             std::to_string(L.maxStorageBufferRange) + " (process in chunks)");
      glBindBufferRange(GL_SHADER_STORAGE_BUFFER, storageIndex(bb.slot), b.name, static_cast<GLintptr>(bb.offset),
                        static_cast<GLsizeiptr>(size));
    }

    glUseProgram(prog.name);
    Pending rec{std::string(d.label.empty() ? d.kernel : d.label), 0, 0, -1};
    // A pair of GL_TIMESTAMP counters, not a GL_TIME_ELAPSED query: llvmpipe's elapsed time covers only
    // rasterizer scenes and gives 0 or garbage for compute, while its timestamps bracket the dispatch,
    // which llvmpipe runs to completion before returning.
    std::chrono::steady_clock::time_point t0;
    if (hostTimed_) {
      waitIdle("dispatch");   // the work before it, not timed with it (bounded, as every wait)
      t0 = std::chrono::steady_clock::now();
    } else if (L.timestamps) {
      rec.begin = takeQuery();
      rec.end = takeQuery();
      glQueryCounter(rec.begin, GL_TIMESTAMP);
    }
    glDispatchCompute(d.groups[0], d.groups[1], d.groups[2]);
    if (rec.end) glQueryCounter(rec.end, GL_TIMESTAMP);
    if (hostTimed_) {
      waitIdle("dispatch");
      rec.hostMs = msSince(t0);
    }
    pending_.push_back(std::move(rec));
    dirty_ = true;
    checkGl("dispatch of " + what);
  }

  void barrier() override {
    activate();
    glMemoryBarrier(kAllBarriers);
    dirty_ = false;
    checkGl("barrier");
  }

  void finish() override {
    activate();
    waitIdle("finish");
    checkGl("finish");
  }

  // Waits for every command issued so far, at most the device timeout (core/device_timeout.h).
  void waitIdle(const char* what) {
    GLsync sync = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    if (!sync) return checkGl(what);
    const GLenum r = glClientWaitSync(sync, GL_SYNC_FLUSH_COMMANDS_BIT, deviceTimeoutNs());
    glDeleteSync(sync);
    if (r == GL_TIMEOUT_EXPIRED) {
      hung_ = true;
      throw deviceError(deviceTimeoutMessage(info_.name));
    }
    checkGl(what);
  }

  std::vector<DispatchTiming> takeTimings() override {
    activate();
    std::vector<DispatchTiming> out;
    if (!pending_.empty()) waitIdle("timings");   // the query results below are then ready
    out.reserve(pending_.size());
    for (Pending& p : pending_) {
      DispatchTiming t;
      t.label = std::move(p.label);
      if (p.hostMs >= 0) t.gpuMs = p.hostMs;
      if (p.begin) {
        GLuint64 t0 = 0, t1 = 0;
        glGetQueryObjectui64v(p.begin, GL_QUERY_RESULT, &t0);   // waits for the result
        glGetQueryObjectui64v(p.end, GL_QUERY_RESULT, &t1);
        t.gpuMs = t1 >= t0 ? static_cast<double>(t1 - t0) * 1e-6 : 0.0;
        freeQueries_.push_back(p.begin);
        freeQueries_.push_back(p.end);
      }
      out.push_back(std::move(t));
    }
    pending_.clear();
    checkGl("takeTimings");
    return out;
  }

 private:
  struct Buf {
    GLuint name = 0;
    uint64_t size = 0;
  };
  struct Pending {
    std::string label;
    GLuint begin = 0, end = 0;   // GL_TIMESTAMP queries around the dispatch (0: no timing)
    double hostMs = -1;          // the dispatch timed on the host (hostTimed_), else -1
  };
  static constexpr uint64_t kRingBytes = 64 * 1024;
  // Everything later work may consume: storage and uniform reads, buffer transfers, indirect commands,
  // and vertex/index fetch (the viewer draws from the output buffers).
  static constexpr GLbitfield kAllBarriers = GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT |
                                             GL_UNIFORM_BARRIER_BIT | GL_COMMAND_BARRIER_BIT |
                                             GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | GL_ELEMENT_ARRAY_BARRIER_BIT;

  const Buf& buffer(BufferId id, uint64_t offset, uint64_t bytes, const char* what) const {
    auto it = buffers_.find(id);
    if (it == buffers_.end())
      throw Error(ErrorKind::Internal, std::string("gl: ") + what + " of unknown buffer " + std::to_string(id));
    if (offset > it->second.size || bytes > it->second.size - offset)
      throw Error(ErrorKind::Internal, std::string("gl: ") + what + " of bytes " + std::to_string(offset) + ".." +
                                           std::to_string(offset + bytes) + " of a " +
                                           std::to_string(it->second.size) + "-byte buffer");
    return it->second;
  }

  // The GL binding index of a storage slot (layout.h numbers them from 1 after the parameter block, as
  // Vulkan's shared namespace needs; ES kernels number them from 0, prelude.glsl's SFFD_SSBO).
  GLuint storageIndex(uint32_t slot) const { return es_ ? slot - 1 : slot; }

  // Makes the context current here and deletes the buffers destroyBuffer could not.
  void activate() {
    ctx_->activate();
    if (orphans_.empty()) return;
    glDeleteBuffers(static_cast<GLsizei>(orphans_.size()), orphans_.data());
    orphans_.clear();
  }

  GLuint takeQuery() {
    if (freeQueries_.empty()) {
      GLuint q[16];
      glGenQueries(16, q);
      freeQueries_.assign(q, q + 16);
    }
    GLuint q = freeQueries_.back();
    freeQueries_.pop_back();
    return q;
  }

  std::shared_ptr<Context> ctx_;
  DeviceInfo info_;
  std::unordered_map<BufferId, Buf> buffers_;
  BufferId nextId_ = 1;
  std::unique_ptr<Programs> programs_;
  GLuint ubo_ = 0;
  uint64_t uboSize_ = 0, uboHead_ = 0, uboAlign_ = 256, maxParams_ = 16384;
  std::vector<Pending> pending_;
  std::vector<GLuint> freeQueries_;
  std::vector<GLuint> orphans_;   // buffers destroyed while the context could not be made current
  bool dirty_ = false;   // dispatches since the last barrier
  bool es_ = false;                // an OpenGL ES context (the gles backend)
  bool heldToEsMinimum_ = false;   // es_, and held to the ES 3.1 minimum limits (gl_es_limits.h)
  bool hostTimed_ = false;         // dispatches timed on the host: the driver's timestamps do not bracket them (OSMesa)
  bool hung_ = false;    // a wait timed out: the device may still use our objects
};

// Whether the gles backend uses the device's own limits: asked for, or SFFD_GLES_LIMITS=device (=minimum: not).
bool useDeviceLimits(bool asked) {
  checkGlesLimitsVariable();
  const char* env = std::getenv("SFFD_GLES_LIMITS");
  return env && *env ? std::string_view(env) == "device" : asked;
}

// A backend of one explicit provider, refused when its renderer does not match the device substring.
std::unique_ptr<Backend> backendOf(Provider provider, const std::string& deviceSubstring, bool deviceLimits = false) {
  auto backend = std::make_unique<GlBackend>(std::shared_ptr<Context>(createContext(provider)), useDeviceLimits(deviceLimits));
  if (!deviceSubstring.empty() && lower(backend->info().name).find(lower(deviceSubstring)) == std::string::npos)
    throw deviceError("gl/" + backend->info().provider + ": renderer '" + backend->info().name +
                      "' does not contain '" + deviceSubstring + "'");
  return backend;
}

}  // namespace

void checkGlesLimitsVariable() { checkVariableIsOneOf("SFFD_GLES_LIMITS", {"minimum", "device"}); }

bool doublesLoseBits(std::string_view vendor) { return vendor.find("NVIDIA") != std::string_view::npos; }

std::unique_ptr<Backend> createBackend(const Options& options) {
  Provider provider = options.provider;
  if (provider == Provider::Auto) provider = providerFromEnvironment();
  if (provider != Provider::Auto) return backendOf(provider, options.deviceSubstring, options.deviceLimits);
  std::string reasons;
  for (Provider p : {Provider::EGL, Provider::OSMesa}) {
    try {
      return backendOf(p, options.deviceSubstring);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::Device) throw;
      reasons += (reasons.empty() ? "" : "; ") + std::string(e.what());
    }
  }
  throw deviceError("gl: no usable OpenGL 4.3+ core context: " + reasons);
}

std::unique_ptr<Backend> createBackendOn(std::shared_ptr<Context> context) {
  if (!context) throw Error(ErrorKind::Internal, "gl: createBackendOn without a context");
  return std::make_unique<GlBackend>(std::move(context), useDeviceLimits(false));
}

const ProgramResources& programResources(Backend& backend, std::string_view kernel, KernelVariant variant) {
  auto* gl = dynamic_cast<GlBackend*>(&backend);
  if (!gl) throw Error(ErrorKind::Internal, "programResources: not a GL backend");
  return gl->resources(kernel, variant);
}

unsigned glBufferObject(const Backend& backend, BufferId buffer) {
  const auto* gl = dynamic_cast<const GlBackend*>(&backend);
  return gl ? gl->bufferObject(buffer) : 0;
}

std::vector<DeviceInfo> listDevices() {
  std::vector<DeviceInfo> out;
  std::string reasons;
  for (Provider p : {Provider::EGL, Provider::OSMesa}) {
    try {
      out.push_back(backendOf(p, "")->info());
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::Device) throw;
      reasons += (reasons.empty() ? "" : "; ") + std::string(e.what());
    }
  }
  if (out.empty()) throw deviceError("gl: no usable OpenGL 4.3+ core context: " + reasons);
  return out;
}

}  // namespace sffd::gl
