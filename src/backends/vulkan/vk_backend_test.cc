// Tests of the Vulkan driver on whatever device the machine has (lavapipe in CI), with the
// validation layer on: every test ends with no validation message. What every backend must do is
// checked in ../backend_contract_test.cc, the staging path of discrete GPUs included.
#include "backends/vulkan/vk_backend.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <sffd/error.h>
#include "backends/backend_test_support.h"
#include "core/shader_binary_cache.h"
#include "tests/support/scoped_env.h"
#include "kernels/common/shader_layout.h"

namespace sffd {
namespace {

using test::ScopedEnv;

class VkBackendTest : public ::testing::Test {
 protected:
  void SetUp() override { setenv("SFFD_VK_VALIDATION", "1", 1); }
  void TearDown() override { EXPECT_EQ(vk::validationMessageCount(), 0u); }
};

using sffd::testing::errorKindOf;

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

gpu::ClassicParams identityParams(uint32_t first, uint32_t count, uint32_t normalsAt) {
  gpu::ClassicParams p{};
  p.lattice.degree = {1, 1, 1, SFFD_OUTSIDE_EXTRAPOLATE};
  p.lattice.boxes = {1, 1, 1, 8};
  p.lattice.break_offset = {SFFD_FRAME_BREAKS, SFFD_FRAME_BREAKS + 2, SFFD_FRAME_BREAKS + 4, 0};
  p.range = {first, count, normalsAt, 0};
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

// Buffers of one classic_ffd job on the identity lattice: vertices in and out, each the positions
// then the normals from element n.
template <typename T>
struct ClassicJob {
  Backend& gpu;
  size_t n;
  BufferId coeffs, frame, vertIn, vertOut;
  std::vector<T> pos, nrm;

  ClassicJob(Backend& backend, size_t count) : gpu(backend), n(count) {
    std::vector<T> c = identityCoeffs<T>(), f = identityFrame<T>();
    coeffs = upload(c);
    frame = upload(f);
    makeVertices(n, pos, nrm);
    std::vector<T> vertices = pos;
    vertices.insert(vertices.end(), nrm.begin(), nrm.end());
    vertIn = upload(vertices);
    vertOut = gpu.createBuffer(2 * bytes());
  }
  ~ClassicJob() {
    for (BufferId b : {coeffs, frame, vertIn, vertOut}) gpu.destroyBuffer(b);
  }
  uint64_t bytes() const { return 4 * n * sizeof(T); }
  BufferId upload(const std::vector<T>& v) {
    BufferId b = gpu.createBuffer(v.size() * sizeof(T));
    gpu.upload(b, 0, v.data(), v.size() * sizeof(T));
    return b;
  }
  // Dispatch over vertices [first, first+count) of the bound buffers.
  void dispatch(KernelVariant variant, uint32_t first, uint32_t count, BufferId in, BufferId out, std::string label = {}) {
    gpu::ClassicParams params = identityParams(first, count, uint32_t(n));
    Dispatch d;
    d.kernel = "classic_ffd";
    d.variant = variant;
    d.params = &params;
    d.paramsSize = sizeof(params);
    d.buffers = {{SFFD_BINDING_LATTICE_COEFFS, coeffs}, {SFFD_BINDING_LATTICE_FRAME, frame},
                 {SFFD_BINDING_CLASSIC_IN, in}, {SFFD_BINDING_CLASSIC_OUT, out}};
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
    std::vector<T> p = download(vertOut, first, count), m = download(vertOut, n + first, count);
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
  SFFD_SKIP_WITHOUT("vulkan");
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
  SFFD_SKIP_WITHOUT("vulkan");
  std::string name = vk::listDevices().front().name;
  std::string upper = name.substr(0, 4);
  for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(vk::createBackend({upper})->info().name.substr(0, 4), name.substr(0, 4));
  EXPECT_EQ(errorKindOf([] { vk::createBackend({"no such device 42"}); }), ErrorKind::Device);
}

template <typename T>
void runIdentity(Backend& gpu, KernelVariant variant, double tol) {
  ClassicJob<T> job(gpu, 1000);
  job.dispatch(variant, 0, 1000, job.vertIn, job.vertOut);
  job.expectIdentity(0, 1000, tol);
}

// A device without shaderFloat64 (simulated with SFFD_VK_DISABLE_F64=1) refuses f64 kernels with a
// device Error and still runs the float ones.
TEST_F(VkBackendTest, RefusesF64WithoutShaderFloat64) {
  SFFD_SKIP_WITHOUT("vulkan");
  ScopedEnv env("SFFD_VK_DISABLE_F64", "1");
  auto gpu = vk::createBackend({});
  EXPECT_FALSE(gpu->info().limits.float64);
  EXPECT_EQ(errorKindOf([&] { runIdentity<double>(*gpu, {false, true}, 0); }), ErrorKind::Device);
  EXPECT_EQ(errorKindOf([&] { runIdentity<double>(*gpu, {true, true}, 0); }), ErrorKind::Device);
  runIdentity<float>(*gpu, {true, false}, 1e-6);
}

// Validation requested but the layer is not installed: one warning, and the backend works.
TEST_F(VkBackendTest, RunsWithoutValidationLayer) {
  SFFD_SKIP_WITHOUT("vulkan");
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

// The output of classic_ffd on the identity lattice, strict and fast (and double where the device has it).
std::vector<float> classicOutputs(Backend& gpu) {
  std::vector<float> out;
  for (bool strict : {true, false}) {
    ClassicJob<float> job(gpu, 300);
    job.dispatch({.strict = strict}, 0, 300, job.vertIn, job.vertOut);
    std::vector<float> v = job.download(job.vertOut, 0, 600);
    out.insert(out.end(), v.begin(), v.end());
  }
  if (gpu.info().limits.float64) {
    ClassicJob<double> job(gpu, 300);
    job.dispatch({.strict = true, .f64 = true}, 0, 300, job.vertIn, job.vertOut);
    for (double d : job.download(job.vertOut, 0, 600)) out.push_back(float(d));
  }
  return out;
}

// Where the driver has VK_EXT_shader_object (Mesa 25's lavapipe: scripts/mesa.sh run -- sffd_vk_tests),
// a backend with a shader cache stores each kernel's binary, the next one makes its kernels from them,
// and damaged files are rebuilt from the SPIR-V: the same bits every time, and the same as pipelines'.
TEST_F(VkBackendTest, ShaderCacheKeepsTheDriversBinariesForTheNextBackend) {
  SFFD_SKIP_WITHOUT("vulkan");
  ScopedEnv noValidation("SFFD_VK_VALIDATION", "0");   // the system's layer may predate the extension
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("sffd-vk-shader-cache-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::vector<float> pipelines = classicOutputs(*vk::createBackend({.shaderCache = "none"}));
  auto withCache = vk::createBackend({.shaderCache = dir.string()});
  if (withCache->info().shaderCache.empty()) {   // pipelines: the driver has no shader objects
    fs::remove_all(dir);
    GTEST_SKIP() << withCache->info().driver << " has no VK_EXT_shader_object";
  }
  auto files = [&] {
    std::map<fs::path, uintmax_t> sizes;
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) sizes[e.path()] = e.file_size();
    return sizes;
  };
  ShaderBinaryCache::Counts c0 = ShaderBinaryCache::counts();
  EXPECT_EQ(classicOutputs(*withCache), pipelines);
  withCache.reset();
  ShaderBinaryCache::Counts c1 = ShaderBinaryCache::counts();
  const size_t variants = c1.stores - c0.stores;
  EXPECT_GE(variants, 2u);
  EXPECT_EQ(c1.misses - c0.misses, variants);
  const std::map<fs::path, uintmax_t> stored = files();
  EXPECT_EQ(stored.size(), variants);

  EXPECT_EQ(classicOutputs(*vk::createBackend({.shaderCache = dir.string()})), pipelines);
  ShaderBinaryCache::Counts c2 = ShaderBinaryCache::counts();
  EXPECT_EQ(c2.hits - c1.hits, variants);
  EXPECT_EQ(c2.stores, c1.stores);

  // Damaged: each file cut short, or its binary's bytes changed where the driver itself would not notice.
  bool cut = true;
  for (const auto& [path, bytes] : stored) {
    if (cut) {
      fs::resize_file(path, bytes / 2);
    } else {
      std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
      f.seekp(std::streamoff(bytes - 8));
      f.write("garbage!", 8);
    }
    cut = !cut;
  }
  EXPECT_EQ(classicOutputs(*vk::createBackend({.shaderCache = dir.string()})), pipelines);
  ShaderBinaryCache::Counts c3 = ShaderBinaryCache::counts();
  EXPECT_EQ(c3.misses - c2.misses, variants);
  EXPECT_EQ(c3.stores - c2.stores, variants);
  EXPECT_EQ(files(), stored);   // whole again
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd
