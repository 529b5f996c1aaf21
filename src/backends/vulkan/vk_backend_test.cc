// Tests of the Vulkan driver on whatever device the machine has (lavapipe in CI), with the
// validation layer on: every test ends with no validation message.
#include "backends/vulkan/vk_backend.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <sffd/error.h>
#include "kernels/common/shader_layout.h"

namespace sffd {
namespace {

// Sets an environment variable for one scope and restores the previous value.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

class VkBackendTest : public ::testing::Test {
 protected:
  void SetUp() override { setenv("SFFD_VK_VALIDATION", "1", 1); }
  void TearDown() override { EXPECT_EQ(vk::validationMessageCount(), 0u); }
};

// Error kind of what `f` throws; fails the test when it throws nothing or something else.
template <typename F>
std::optional<ErrorKind> errorKindOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_FALSE(std::string(e.what()).empty());
    return e.kind();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an sffd::Error: " << e.what();
    return std::nullopt;
  }
  ADD_FAILURE() << "nothing was thrown";
  return std::nullopt;
}

// ---- the identity lattice: degree 1 on each axis, one knot box over [0,1]^3 ----

template <typename T>
std::vector<T> identityFrame() {
  std::vector<T> f = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0,    // affine rows
                      1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0,    // cof(A) rows
                      0, 1, 0, 1, 0, 1};                     // breaks of u, v, w
  return f;
}

template <typename T>
std::vector<T> identityCoeffs() {
  std::vector<T> c;
  for (int p = 0; p < 2; ++p)
    for (int q = 0; q < 2; ++q)
      for (int r = 0; r < 2; ++r) c.insert(c.end(), {T(p), T(q), T(r), T(0)});   // index (p*2+q)*2+r
  return c;
}

gpu::ClassicParams identityParams(uint32_t first, uint32_t count) {
  gpu::ClassicParams p{};
  p.lattice.degree = {1, 1, 1, SFFD_OUTSIDE_EXTRAPOLATE};
  p.lattice.boxes = {1, 1, 1, 8};
  p.lattice.break_offset = {SFFD_FRAME_BREAKS, SFFD_FRAME_BREAKS + 2, SFFD_FRAME_BREAKS + 4, 0};
  p.range = {first, count, 0, 0};
  return p;
}

// Deterministic points strictly inside the unit cube and unit normals, real4 each.
template <typename T>
void makeVertices(size_t n, std::vector<T>& pos, std::vector<T>& nrm) {
  pos.resize(4 * n);
  nrm.resize(4 * n);
  uint32_t h = 12345;
  auto next = [&] {
    h = h * 1664525u + 1013904223u;
    return double(h >> 8) / double(1u << 24);
  };
  for (size_t i = 0; i < n; ++i) {
    double x = 0.01 + 0.98 * next(), y = 0.01 + 0.98 * next(), z = 0.01 + 0.98 * next();
    double a = next() - 0.5, b = next() - 0.5, c = next() - 0.5 + 1e-3;
    double len = std::sqrt(a * a + b * b + c * c);
    T* p = &pos[4 * i];
    T* m = &nrm[4 * i];
    p[0] = T(x), p[1] = T(y), p[2] = T(z), p[3] = T(1);
    m[0] = T(a / len), m[1] = T(b / len), m[2] = T(c / len), m[3] = T(0);
  }
}

// Buffers of one classic_ffd job on the identity lattice.
template <typename T>
struct ClassicJob {
  Backend& gpu;
  size_t n;
  BufferId coeffs, frame, posIn, nrmIn, posOut, nrmOut;
  std::vector<T> pos, nrm;

  ClassicJob(Backend& backend, size_t count) : gpu(backend), n(count) {
    std::vector<T> c = identityCoeffs<T>(), f = identityFrame<T>();
    coeffs = upload(c);
    frame = upload(f);
    makeVertices(n, pos, nrm);
    posIn = upload(pos);
    nrmIn = upload(nrm);
    posOut = gpu.createBuffer(bytes());
    nrmOut = gpu.createBuffer(bytes());
  }
  ~ClassicJob() {
    for (BufferId b : {coeffs, frame, posIn, nrmIn, posOut, nrmOut}) gpu.destroyBuffer(b);
  }
  uint64_t bytes() const { return 4 * n * sizeof(T); }
  BufferId upload(const std::vector<T>& v) {
    BufferId b = gpu.createBuffer(v.size() * sizeof(T));
    gpu.upload(b, 0, v.data(), v.size() * sizeof(T));
    return b;
  }
  // Dispatch over vertices [first, first+count) of the bound buffers.
  void dispatch(KernelVariant variant, uint32_t first, uint32_t count, BufferId in, BufferId out, std::string label = {}) {
    gpu::ClassicParams params = identityParams(first, count);
    Dispatch d;
    d.kernel = "classic_ffd";
    d.variant = variant;
    d.params = &params;
    d.paramsSize = sizeof(params);
    d.buffers = {{SFFD_BINDING_LATTICE_COEFFS, coeffs}, {SFFD_BINDING_LATTICE_FRAME, frame},
                 {SFFD_BINDING_CLASSIC_POS_IN, in},     {SFFD_BINDING_CLASSIC_NRM_IN, nrmIn},
                 {SFFD_BINDING_CLASSIC_POS_OUT, out},   {SFFD_BINDING_CLASSIC_NRM_OUT, nrmOut}};
    gridFor(count, gpu.info().limits, d.groups);
    d.label = label;
    gpu.dispatch(d);
  }
  std::vector<T> download(BufferId b, size_t first, size_t count) {
    std::vector<T> v(4 * count);
    gpu.download(b, 4 * first * sizeof(T), v.data(), v.size() * sizeof(T));
    return v;
  }
  // Vertices [first, first+count) came out where they went in, with w = 1 (inside), and their
  // normals unchanged and unit.
  void expectIdentity(size_t first, size_t count, double tol) {
    std::vector<T> p = download(posOut, first, count), m = download(nrmOut, first, count);
    for (size_t i = 0; i < count; ++i) {
      const T* in = &pos[4 * (first + i)];
      const T* nin = &nrm[4 * (first + i)];
      for (int k = 0; k < 3; ++k) {
        ASSERT_NEAR(p[4 * i + k], in[k], tol) << "vertex " << first + i << " coordinate " << k;
        ASSERT_NEAR(m[4 * i + k], nin[k], tol) << "normal " << first + i << " coordinate " << k;
      }
      ASSERT_EQ(p[4 * i + 3], T(1)) << "vertex " << first + i << " not reported inside";
      ASSERT_EQ(m[4 * i + 3], T(0));
      double len = std::sqrt(double(m[4 * i]) * m[4 * i] + double(m[4 * i + 1]) * m[4 * i + 1] +
                             double(m[4 * i + 2]) * m[4 * i + 2]);
      ASSERT_NEAR(len, 1.0, tol);
    }
  }
};

TEST_F(VkBackendTest, ListsDevices) {
  std::vector<DeviceInfo> devices = vk::listDevices();
  ASSERT_FALSE(devices.empty());
  for (const DeviceInfo& d : devices) {
    EXPECT_EQ(d.api, "vulkan");
    EXPECT_EQ(d.provider, "vulkan");
    EXPECT_FALSE(d.name.empty());
    EXPECT_FALSE(d.driver.empty());
    EXPECT_GE(d.limits.maxStorageBufferRange, 1u << 20);
    EXPECT_GE(d.limits.maxWorkGroupCount[0], 65535u);
    std::printf("device: %s [%s] %s, storage range %llu, float64 %d, timestamps %d\n", d.name.c_str(), d.type.c_str(),
                d.driver.c_str(), (unsigned long long)d.limits.maxStorageBufferRange, d.limits.float64,
                d.limits.timestamps);
  }
}

TEST_F(VkBackendTest, PicksDeviceBySubstring) {
  std::string name = vk::listDevices().front().name;
  std::string upper = name.substr(0, 4);
  for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(vk::createBackend({upper})->info().name.substr(0, 4), name.substr(0, 4));
  EXPECT_EQ(errorKindOf([] { vk::createBackend({"no such device 42"}); }), ErrorKind::Device);
}

// Upload and download with offsets, on mapped memory and through staging buffers (the path of
// discrete GPUs, forced by SFFD_VK_STAGING=1).
TEST_F(VkBackendTest, BufferRoundTrip) {
  for (const char* staging : {"0", "1"}) {
    SCOPED_TRACE(std::string("SFFD_VK_STAGING=") + staging);
    ScopedEnv env("SFFD_VK_STAGING", staging);
    auto gpu = vk::createBackend({});
    const size_t n = 1 << 18;
    std::vector<uint32_t> data(n);
    for (size_t i = 0; i < n; ++i) data[i] = uint32_t(i * 2654435761u);
    BufferId a = gpu->createBuffer(n * 4);
    BufferId b = gpu->createBuffer(100);
    EXPECT_NE(a, 0u);
    EXPECT_NE(a, b);
    gpu->upload(a, 0, data.data(), n * 4);
    std::vector<uint32_t> patch = {1, 2, 3, 4, 5};
    gpu->upload(a, 4000, patch.data(), patch.size() * 4);
    std::copy(patch.begin(), patch.end(), data.begin() + 1000);

    std::vector<uint32_t> all(n), part(7);
    gpu->download(a, 0, all.data(), n * 4);
    EXPECT_EQ(all, data);
    gpu->download(a, 3996, part.data(), part.size() * 4);
    EXPECT_EQ(part, std::vector<uint32_t>(data.begin() + 999, data.begin() + 1006));

    gpu->destroyBuffer(a);
    BufferId c = gpu->createBuffer(16);   // ids are reused
    EXPECT_EQ(c, a);
    EXPECT_EQ(errorKindOf([&] { gpu->download(b, 96, part.data(), 8); }), ErrorKind::Internal);   // overrun
    EXPECT_EQ(errorKindOf([&] { gpu->upload(12345, 0, part.data(), 4); }), ErrorKind::Internal);   // bad id
    gpu->destroyBuffer(b);
    gpu->destroyBuffer(c);
  }
}

template <typename T>
void runIdentity(Backend& gpu, KernelVariant variant, double tol) {
  ClassicJob<T> job(gpu, 1000);
  job.dispatch(variant, 0, 1000, job.posIn, job.posOut);
  job.expectIdentity(0, 1000, tol);
}

// classic_ffd in its four variants on the identity lattice.
TEST_F(VkBackendTest, ClassicFfdIdentityAllVariants) {
  for (const char* staging : {"0", "1"}) {
    ScopedEnv env("SFFD_VK_STAGING", staging);
    auto gpu = vk::createBackend({});
    for (bool f64 : {false, true})
      for (bool strict : {false, true}) {
        SCOPED_TRACE(std::string("staging ") + staging + ", strict " + std::to_string(strict) + ", f64 " +
                     std::to_string(f64));
        KernelVariant v{strict, f64};
        if (f64 && !gpu->info().limits.float64) {
          EXPECT_EQ(errorKindOf([&] { runIdentity<double>(*gpu, v, 0); }), ErrorKind::Device);
          continue;
        }
        if (f64)
          runIdentity<double>(*gpu, v, 1e-12);
        else
          runIdentity<float>(*gpu, v, 1e-6);
      }
    std::vector<DispatchTiming> t = gpu->takeTimings();
    EXPECT_EQ(t.size(), gpu->info().limits.float64 ? 4u : 2u);
    EXPECT_TRUE(gpu->takeTimings().empty());
  }
}

// A device without shaderFloat64 (simulated with SFFD_VK_DISABLE_F64=1) refuses f64 kernels with a
// device Error and still runs the float ones.
TEST_F(VkBackendTest, RefusesF64WithoutShaderFloat64) {
  ScopedEnv env("SFFD_VK_DISABLE_F64", "1");
  auto gpu = vk::createBackend({});
  EXPECT_FALSE(gpu->info().limits.float64);
  EXPECT_EQ(errorKindOf([&] { runIdentity<double>(*gpu, {false, true}, 0); }), ErrorKind::Device);
  EXPECT_EQ(errorKindOf([&] { runIdentity<double>(*gpu, {true, true}, 0); }), ErrorKind::Device);
  runIdentity<float>(*gpu, {true, false}, 1e-6);
}

TEST_F(VkBackendTest, UnknownKernelIsInternalError) {
  auto gpu = vk::createBackend({});
  Dispatch d;
  d.kernel = "no_such_kernel";
  EXPECT_EQ(errorKindOf([&] { gpu->dispatch(d); }), ErrorKind::Internal);
  gpu->finish();
}

// Recorded work runs in order: an upload after a dispatch does not change what the dispatch read,
// a barrier orders dependent dispatches, and download sees everything without an explicit finish.
TEST_F(VkBackendTest, OrdersUploadsDispatchesAndDownloads) {
  for (const char* staging : {"0", "1"}) {
    SCOPED_TRACE(std::string("SFFD_VK_STAGING=") + staging);
    ScopedEnv env("SFFD_VK_STAGING", staging);
    auto gpu = vk::createBackend({});
    const size_t n = 5000;
    ClassicJob<float> job(*gpu, n);
    BufferId second = gpu->createBuffer(job.bytes()), third = gpu->createBuffer(job.bytes());
    job.dispatch({}, 0, n, job.posIn, job.posOut);   // posOut = pos
    std::vector<float> shifted = job.pos;
    for (size_t i = 0; i < 4 * n; i += 4) shifted[i] = 0.5f * shifted[i];
    gpu->upload(job.posIn, 0, shifted.data(), shifted.size() * sizeof(float));
    job.dispatch({}, 0, n, job.posIn, second);   // second = shifted
    gpu->barrier();
    job.dispatch({}, 0, n, second, third);       // third = second, after the barrier
    job.expectIdentity(0, n, 1e-6);
    std::vector<float> s = job.download(second, 0, n), t = job.download(third, 0, n);
    for (size_t i = 0; i < 4 * n; ++i) {
      ASSERT_NEAR(s[i], shifted[i], 1e-6) << i;
      ASSERT_NEAR(t[i], shifted[i], 1e-6) << i;
    }
    gpu->destroyBuffer(second);
    gpu->destroyBuffer(third);
  }
}

// Many chunked dispatches in one submission (more than one descriptor pool, query pool and
// parameter chunk), each with its own parameter block, and one timing record per dispatch.
TEST_F(VkBackendTest, ManyDispatchesInOneSubmission) {
  auto gpu = vk::createBackend({});
  const uint32_t chunks = 700, chunk = 64;
  ClassicJob<float> job(*gpu, chunks * chunk);
  for (uint32_t c = 0; c < chunks; ++c)
    job.dispatch({}, c * chunk, chunk, job.posIn, job.posOut, c == 0 ? "first chunk" : "");
  gpu->finish();
  job.expectIdentity(0, chunks * chunk, 1e-6);
  std::vector<DispatchTiming> t = gpu->takeTimings();
  ASSERT_EQ(t.size(), chunks);
  EXPECT_EQ(t.front().label, "first chunk");
  EXPECT_EQ(t.back().label, "classic_ffd");
  for (const DispatchTiming& d : t) EXPECT_EQ(d.gpuMs >= 0, gpu->info().limits.timestamps);
}

// A 1-D job too large for one grid row: 4.2M vertices need 65625 groups of 64 threads.
TEST_F(VkBackendTest, LargeJobUsesTwoDimensionalGrid) {
  auto gpu = vk::createBackend({});
  const uint32_t n = 4200000;
  uint32_t groups[3];
  gridFor(n, gpu->info().limits, groups);
  EXPECT_GT(groups[1], 1u);
  EXPECT_GE(uint64_t(groups[0]) * groups[1] * SFFD_LOCAL_SIZE, n);
  ClassicJob<float> job(*gpu, n);
  job.dispatch({}, 0, 64, job.posIn, job.posOut, "warm-up");   // compiles the kernel (llvmpipe JITs at first use)
  gpu->finish();
  gpu->takeTimings();
  job.dispatch({}, 0, n, job.posIn, job.posOut, "large");
  job.expectIdentity(0, 1000, 1e-6);
  job.expectIdentity(n - 70000, 70000, 1e-6);   // the vertices in the second grid row
  std::vector<DispatchTiming> t = gpu->takeTimings();
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].label, "large");
  if (gpu->info().limits.timestamps) {
    EXPECT_GT(t[0].gpuMs, 0);
  }
  std::printf("classic_ffd, %u vertices, float: %.2f ms on %s\n", n, t[0].gpuMs, gpu->info().name.c_str());
}

// A buffer destroyed while recorded work still uses it lives until that work has run.
TEST_F(VkBackendTest, DestroyBufferWithPendingWork) {
  for (const char* staging : {"0", "1"}) {
    ScopedEnv env("SFFD_VK_STAGING", staging);
    auto gpu = vk::createBackend({});
    ClassicJob<float> job(*gpu, 256);
    BufferId scratch = gpu->createBuffer(job.bytes());
    gpu->upload(scratch, 0, job.pos.data(), job.bytes());
    job.dispatch({}, 0, 256, scratch, job.posOut);
    gpu->destroyBuffer(scratch);
    job.expectIdentity(0, 256, 1e-6);
  }
}

// Validation requested but the layer is not installed: one warning, and the backend works.
TEST_F(VkBackendTest, RunsWithoutValidationLayer) {
  ScopedEnv layers("VK_LAYER_PATH", "/nonexistent");
  auto gpu = vk::createBackend({"", true});
  runIdentity<float>(*gpu, {}, 1e-6);
}

TEST_F(VkBackendTest, MissingLoaderIsDeviceError) {
  ScopedEnv env("SFFD_VULKAN_LIBRARY", "libvulkan-sffd-test-missing.so.1");
  EXPECT_EQ(errorKindOf([] { vk::createBackend({}); }), ErrorKind::Device);
  EXPECT_EQ(errorKindOf([] { vk::listDevices(); }), ErrorKind::Device);
}

TEST_F(VkBackendTest, MissingDriverIsDeviceError) {
  ScopedEnv files("VK_DRIVER_FILES", "/nonexistent/sffd.json");
  ScopedEnv icds("VK_ICD_FILENAMES", "/nonexistent/sffd.json");
  EXPECT_EQ(errorKindOf([] { vk::createBackend({}); }), ErrorKind::Device);
  EXPECT_EQ(errorKindOf([] { vk::listDevices(); }), ErrorKind::Device);
}

}  // namespace
}  // namespace sffd
