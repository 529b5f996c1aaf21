// The Backend interface's contract (src/core/backend.h), checked on every backend that opens here:
// buffers, bound ranges, variants, barriers, timings and errors, with the classic_ffd kernel on a
// hand-built lattice. "vulkan-staging" is Vulkan with SFFD_VK_STAGING=1, the transfer path of discrete
// GPUs. API-specific tests stay in vulkan/vk_backend_test.cc and opengl/gl_backend_test.cc.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <sffd/error.h>
#include "backends/backend_select.h"
#include "backends/backend_test_support.h"
#include "backends/classic_test_inputs.h"
#include "backends/vulkan/vk_backend.h"
#include "core/kernel_registry.h"
#include "kernels/classic/classic_ffd.h"
#include "kernels/common/shader_layout.h"

namespace sffd {
namespace {

using testing::HandLattice;
using testing::makeVertices;

// The buffers of one classic_ffd job: lattice, vertices in, vertices out (positions, then normals
// from element n: layout.h, ClassicParams).
template <class Real>
struct ClassicJob {
  Backend& b;
  size_t n;
  HandLattice<Real> lattice;
  std::vector<Real> pos, nrm;
  BufferId coeffs, frame, vertIn, vertOut;

  ClassicJob(Backend& backend, size_t count, size_t inside, bool moved = false) : b(backend), n(count), lattice(moved) {
    makeVertices(n, inside, pos, nrm);
    coeffs = upload(lattice.coeffs);
    frame = upload(lattice.frame);
    vertIn = upload(vertices());
    vertOut = b.createBuffer(2 * bytes());
  }
  ~ClassicJob() {
    for (BufferId id : {coeffs, frame, vertIn, vertOut}) b.destroyBuffer(id);
  }
  uint64_t bytes() const { return 4 * n * sizeof(Real); }
  std::vector<Real> vertices() const {
    std::vector<Real> v = pos;
    v.insert(v.end(), nrm.begin(), nrm.end());
    return v;
  }
  BufferId upload(const std::vector<Real>& v) {
    BufferId id = b.createBuffer(v.size() * sizeof(Real));
    b.upload(id, 0, v.data(), v.size() * sizeof(Real));
    return id;
  }
  gpu::ClassicParams params(uint32_t first, uint32_t count, size_t normalsAt = 0) const {
    gpu::ClassicParams p;
    p.lattice = lattice.params;
    p.range = {first, count, uint32_t(normalsAt ? normalsAt : n), 0};
    return p;
  }
  Dispatch dispatchOf(KernelVariant v, const gpu::ClassicParams& p, BufferId in, BufferId out) const {
    Dispatch d;
    d.kernel = "classic_ffd";
    d.variant = v;
    d.params = &p;
    d.paramsSize = sizeof p;
    d.buffers = {{SFFD_BINDING_LATTICE_COEFFS, coeffs}, {SFFD_BINDING_LATTICE_FRAME, frame},
                 {SFFD_BINDING_CLASSIC_IN, in}, {SFFD_BINDING_CLASSIC_OUT, out}};
    gridFor(p.range.y, b.info().limits, d.groups);
    return d;
  }
  // Vertices [first, first+count) of the bound buffers.
  void dispatch(KernelVariant v, uint32_t first, uint32_t count, BufferId in, BufferId out, std::string_view label = {}) {
    gpu::ClassicParams p = params(first, count);
    Dispatch d = dispatchOf(v, p, in, out);
    d.label = label;
    b.dispatch(d);
  }
  std::vector<Real> download(BufferId id, size_t first, size_t count) {
    std::vector<Real> v(4 * count);
    b.download(id, 4 * first * sizeof(Real), v.data(), v.size() * sizeof(Real));
    return v;
  }
  // The identity lattice maps vertices [first, first+count) to themselves (w = 1 inside, 0 outside)
  // and keeps their unit normals.
  void expectIdentity(size_t first, size_t count, size_t inside, double tol) {
    std::vector<Real> p = download(vertOut, first, count), m = download(vertOut, n + first, count);
    for (size_t i = 0; i < count; ++i) {
      const size_t v = first + i;
      for (int k = 0; k < 3; ++k) {
        ASSERT_NEAR(p[4 * i + k], pos[4 * v + k], tol) << "vertex " << v << " axis " << k;
        ASSERT_NEAR(m[4 * i + k], nrm[4 * v + k], tol) << "normal " << v << " axis " << k;
      }
      ASSERT_EQ(p[4 * i + 3], Real(v < inside ? 1 : 0)) << "vertex " << v;
      ASSERT_EQ(m[4 * i + 3], Real(0)) << "normal " << v;
    }
  }
};

using testing::errorKindOf;

class BackendContract : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    const bool staging = GetParam() == "vulkan-staging";
    if (staging) setenv("SFFD_VK_STAGING", "1", 1);   // read when the device is created
    std::string why;
    std::optional<OpenedBackend> opened;
    try {
      opened = sffd::testing::openUnlessAbsent(staging ? "vulkan" : GetParam(), sffd::testing::openForTest, why);
    } catch (...) {
      if (staging) unsetenv("SFFD_VK_STAGING");
      throw;
    }
    if (staging) unsetenv("SFFD_VK_STAGING");
    if (!opened) GTEST_SKIP() << why;
    opened_ = std::move(*opened);
  }
  void TearDown() override { EXPECT_EQ(vk::validationMessageCount(), 0u); }
  Backend& backend() { return *opened_.backend; }

 private:
  OpenedBackend opened_;
};

TEST_P(BackendContract, DescribesItsDevice) {
  const DeviceInfo& info = backend().info();
  for (const std::string* s : {&info.api, &info.provider, &info.name, &info.driver, &info.type}) EXPECT_FALSE(s->empty());
  const DeviceLimits& L = info.limits;
  EXPECT_GE(L.maxStorageBufferRange, 16u << 20);
  EXPECT_GT(L.storageOffsetAlignment, 0u);
  EXPECT_EQ(L.storageOffsetAlignment & (L.storageOffsetAlignment - 1), 0u) << "a power of two";
  for (uint32_t g : L.maxWorkGroupCount) EXPECT_GE(g, 65535u);
}

// Upload and download at offsets, partial reads and writes; out-of-range and unknown buffers are
// internal errors; ids are distinct; a zero-sized buffer exists.
TEST_P(BackendContract, BufferRoundTripWithOffsets) {
  Backend& b = backend();
  const size_t n = 1 << 18;
  std::vector<uint32_t> data(n);
  for (size_t i = 0; i < n; ++i) data[i] = uint32_t(i * 2654435761u);
  BufferId a = b.createBuffer(n * 4), c = b.createBuffer(1000);
  EXPECT_NE(a, 0u);
  EXPECT_NE(a, c);
  b.upload(a, 0, data.data(), n * 4);
  std::vector<uint32_t> patch = {1, 2, 3, 4, 5};
  b.upload(a, 4000, patch.data(), patch.size() * 4);
  std::copy(patch.begin(), patch.end(), data.begin() + 1000);
  std::vector<uint32_t> all(n), part(7);
  b.download(a, 0, all.data(), n * 4);
  EXPECT_EQ(all, data);
  b.download(a, 3996, part.data(), part.size() * 4);
  EXPECT_EQ(part, std::vector<uint32_t>(data.begin() + 999, data.begin() + 1006));

  // Bytes at unaligned offsets.
  std::vector<uint8_t> bytes(1000), back(1000, 0xEE), run(37, 0x5A);
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = uint8_t(i * 7 + 3);
  b.upload(c, 0, bytes.data(), bytes.size());
  b.upload(c, 101, run.data(), run.size());
  std::fill(bytes.begin() + 101, bytes.begin() + 138, 0x5A);
  b.download(c, 77, back.data(), 300);
  EXPECT_TRUE(std::equal(back.begin(), back.begin() + 300, bytes.begin() + 77));
  b.download(c, 999, back.data(), 1);
  EXPECT_EQ(back[0], bytes[999]);

  EXPECT_EQ(errorKindOf([&] { b.upload(c, 990, run.data(), 11); }), ErrorKind::Internal);   // overrun
  EXPECT_EQ(errorKindOf([&] { b.download(c, 1001, back.data(), 0); }), ErrorKind::Internal);
  EXPECT_EQ(errorKindOf([&] { b.download(123456, 0, back.data(), 1); }), ErrorKind::Internal);   // unknown id
  b.destroyBuffer(a);
  b.destroyBuffer(c);
  BufferId empty = b.createBuffer(0);
  b.download(empty, 0, back.data(), 0);
  b.destroyBuffer(empty);
}

// classic_ffd in its four variants on the identity lattice; f64 is refused with a device error where
// the device has no double-precision shaders. Returns how many ran.
size_t runClassicVariants(Backend& b) {
  size_t dispatched = 0;
  for (bool f64 : {false, true})
    for (bool strict : {false, true}) {
      SCOPED_TRACE(std::string("strict ") + std::to_string(strict) + ", f64 " + std::to_string(f64));
      KernelVariant v{strict, f64};
      if (f64 && !b.info().limits.float64) {
        ClassicJob<double> job(b, 100, 100);
        EXPECT_EQ(errorKindOf([&] { job.dispatch(v, 0, 100, job.vertIn, job.vertOut); }), ErrorKind::Device);
        continue;
      }
      if (f64) {
        ClassicJob<double> job(b, 1000, 900);
        job.dispatch(v, 0, 1000, job.vertIn, job.vertOut);
        job.expectIdentity(0, 1000, 900, 1e-14);
      } else {
        ClassicJob<float> job(b, 1000, 900);
        job.dispatch(v, 0, 1000, job.vertIn, job.vertOut);
        job.expectIdentity(0, 1000, 900, 1e-6);
      }
      ++dispatched;
    }
  return dispatched;
}

// One timing a dispatch, taken once.
TEST_P(BackendContract, ClassicIdentityInEveryVariant) {
  Backend& b = backend();
  const size_t dispatched = runClassicVariants(b);
  b.finish();
  EXPECT_EQ(b.takeTimings().size(), dispatched);
  EXPECT_TRUE(b.takeTimings().empty());
}

// precompile is a hint: variants built ahead (Vulkan: on other threads; GL: on the driver's compiler
// threads, KHR_parallel_shader_compile) give the same results, and
// what cannot be built (an unknown kernel, f64 without the feature) fails at the dispatch that needs it.
TEST_P(BackendContract, PrecompiledVariantsBehaveAsBuiltOnFirstUse) {
  Backend& b = backend();
  std::vector<KernelUse> uses = {{"no_such_kernel", {}}};
  for (bool f64 : {false, true})
    for (bool strict : {false, true}) uses.push_back({"classic_ffd", {strict, f64}});
  b.precompile(uses);
  b.precompile(uses);   // again, while they may still be building
  runClassicVariants(b);
  ClassicJob<float> job(b, 100, 100);
  const gpu::ClassicParams p = job.params(0, 100);
  Dispatch d = job.dispatchOf({}, p, job.vertIn, job.vertOut);
  d.kernel = "no_such_kernel";
  EXPECT_EQ(errorKindOf([&] { b.dispatch(d); }), ErrorKind::Internal);
  b.finish();
}

// Builds never asked for, a failing one among them, end with the backend (the fixture's TearDown
// checks that Vulkan's validation saw nothing left behind).
TEST_P(BackendContract, UnclaimedPrecompiledBuildsEndWithTheBackend) {
  backend().precompile({{"no_such_kernel", {}}, {"classic_ffd", {}}, {"classic_ffd", {true, true}}});
}

// A build issued ahead and never used stops counting as a compile in flight once the driver is done
// with it (conform's heartbeat reads the count): by itself on Vulkan's workers, at the next dispatch on GL.
TEST_P(BackendContract, UnusedPrecompiledBuildsStopCountingOnceBuilt) {
  Backend& b = backend();
  b.precompile({{"classic_ffd", {true, false}}});   // strict: never dispatched here
  ClassicJob<float> job(b, 100, 100);
  const gpu::ClassicParams p = job.params(0, 100);
  for (int i = 0; i < 200 && oldestCompileInFlightSeconds() >= 0; ++i) {
    b.dispatch(job.dispatchOf({}, p, job.vertIn, job.vertOut));
    b.finish();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_LT(oldestCompileInFlightSeconds(), 0);
}

// Ranges in the middle of one larger buffer, at aligned offsets; bad dispatches are internal errors.
TEST_P(BackendContract, BindsRangesAtAlignedOffsetsAndRefusesBadDispatches) {
  Backend& b = backend();
  const uint64_t align = b.info().limits.storageOffsetAlignment;
  ClassicJob<float> job(b, 100, 100);
  const uint64_t bytes = 2 * job.bytes(), off = 3 * align;
  BufferId big = b.createBuffer(off + 2 * bytes + 2 * align);
  uint64_t at[2];
  for (int k = 0; k < 2; ++k) at[k] = off + k * ((bytes + align - 1) / align * align);
  b.upload(big, at[0], job.vertices().data(), bytes);
  gpu::ClassicParams params = job.params(0, 100);
  Dispatch d = job.dispatchOf({true, false}, params, job.vertIn, job.vertOut);
  d.buffers = {{SFFD_BINDING_LATTICE_COEFFS, job.coeffs}, {SFFD_BINDING_LATTICE_FRAME, job.frame},
               {SFFD_BINDING_CLASSIC_IN, big, at[0], bytes}, {SFFD_BINDING_CLASSIC_OUT, big, at[1], bytes}};
  b.dispatch(d);
  b.barrier();
  std::vector<float> out(job.pos.size());
  b.download(big, at[1], out.data(), job.bytes());
  for (size_t i = 0; i < 4 * 100; ++i) ASSERT_NEAR(out[i], job.pos[i], 1e-6) << i;

  auto expectInternal = [&](const Dispatch& bad, const char* what) {
    EXPECT_EQ(errorKindOf([&] { b.dispatch(bad); }), ErrorKind::Internal) << what;
  };
  if (align > 1) {
    Dispatch bad = d;
    bad.buffers[2].offset = at[0] + 4;
    expectInternal(bad, "misaligned offset");
  }
  Dispatch bad = d;
  bad.buffers[2].size = 100 * bytes;
  expectInternal(bad, "range past the end");
  bad = d;
  bad.buffers[0].slot = SFFD_MAX_STORAGE_BINDINGS + 1;
  expectInternal(bad, "slot out of range");
  bad = d;
  bad.groups[0] = b.info().limits.maxWorkGroupCount[0] + 1;
  expectInternal(bad, "too many groups");
  if (b.info().api != "vulkan") {   // Vulkan records the block without knowing the kernel's size for it
    bad = d;
    bad.paramsSize = 16;
    expectInternal(bad, "short parameter block");
  }
  bad = d;
  bad.kernel = "no_such_kernel";
  expectInternal(bad, "unknown kernel");
  b.finish();
  b.takeTimings();
  b.destroyBuffer(big);
}

// Work runs in order: an upload after a dispatch does not change what the dispatch read, a barrier
// orders dependent dispatches, and a download sees everything without an explicit finish.
TEST_P(BackendContract, BarriersOrderDependentDispatches) {
  Backend& b = backend();
  const size_t n = 5000;
  ClassicJob<float> job(b, n, n);
  BufferId second = b.createBuffer(2 * job.bytes()), third = b.createBuffer(2 * job.bytes());
  job.dispatch({}, 0, n, job.vertIn, job.vertOut);   // posOut = pos
  std::vector<float> shifted = job.pos;
  for (size_t i = 0; i < 4 * n; i += 4) shifted[i] = 0.5f * shifted[i];
  b.upload(job.vertIn, 0, shifted.data(), shifted.size() * sizeof(float));
  job.dispatch({}, 0, n, job.vertIn, second);   // second = shifted
  b.barrier();
  job.dispatch({}, 0, n, second, third);       // third = second, after the barrier
  job.expectIdentity(0, n, n, 1e-6);
  std::vector<float> s = job.download(second, 0, n), t = job.download(third, 0, n);
  for (size_t i = 0; i < 4 * n; ++i) {
    ASSERT_NEAR(s[i], shifted[i], 1e-6) << i;
    ASSERT_NEAR(t[i], shifted[i], 1e-6) << i;
  }
  b.destroyBuffer(second);
  b.destroyBuffer(third);
}

// Many dispatches before a finish, each with its own parameter block: one timing record each, in
// order, labelled by the dispatch's label or else the kernel name; measured where the device says so.
TEST_P(BackendContract, TimesEveryDispatchUnderItsLabel) {
  Backend& b = backend();
  const uint32_t chunks = 700, chunk = 64;
  ClassicJob<float> job(b, chunks * chunk, chunks * chunk);
  for (uint32_t c = 0; c < chunks; ++c) job.dispatch({}, c * chunk, chunk, job.vertIn, job.vertOut, c == 0 ? "first chunk" : "");
  b.finish();
  job.expectIdentity(0, chunks * chunk, chunks * chunk, 1e-6);
  std::vector<DispatchTiming> t = b.takeTimings();
  ASSERT_EQ(t.size(), chunks);
  EXPECT_EQ(t.front().label, "first chunk");
  EXPECT_EQ(t.back().label, "classic_ffd");
  for (const DispatchTiming& d : t) EXPECT_EQ(d.gpuMs >= 0, b.info().limits.timestamps);
}

// A 1-D job beyond 65535 groups of 64 runs as a 2-D grid (gridFor): every vertex written.
TEST_P(BackendContract, LargeJobRunsAsTwoDimensionalGrid) {
  Backend& b = backend();
  // Just past 65535 full groups, and positions and normals (one binding) within 128 MiB.
  const size_t n = size_t(SFFD_MAX_GROUPS_X) * SFFD_LOCAL_SIZE + SFFD_LOCAL_SIZE - 5;
  ClassicJob<float> job(b, 64, 64);
  std::vector<float> pos(4 * n), nrm(4 * n);
  for (size_t i = 0; i < n; ++i) {
    // Distinct points on a 256 x 256 x 64 grid inside the box, exactly representable.
    pos[4 * i + 0] = float(i % 256) / 256.0f;
    pos[4 * i + 1] = float((i / 256) % 256) / 256.0f;
    pos[4 * i + 2] = float((i / 65536) % 64) / 64.0f;
    pos[4 * i + 3] = 1;
    nrm[4 * i + 2] = 1;
  }
  std::vector<float> vertices = pos;
  vertices.insert(vertices.end(), nrm.begin(), nrm.end());
  BufferId in = job.upload(vertices), out = b.createBuffer(vertices.size() * 4);
  gpu::ClassicParams params = job.params(0, uint32_t(n), n);
  Dispatch d = job.dispatchOf({}, params, in, out);
  EXPECT_EQ(d.groups[1], 2u);   // more than 65535 groups of work: a second row
  EXPECT_GE(uint64_t(d.groups[0]) * d.groups[1] * SFFD_LOCAL_SIZE, n);
  d.label = "large";
  auto t0 = std::chrono::steady_clock::now();
  b.dispatch(d);
  b.barrier();
  std::vector<float> p(pos.size()), m(pos.size());
  b.download(out, 0, p.data(), p.size() * 4);
  b.download(out, p.size() * 4, m.data(), m.size() * 4);
  b.finish();
  double wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::vector<DispatchTiming> t = b.takeTimings();
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].label, "large");
  if (b.info().limits.timestamps) {
    EXPECT_GT(t[0].gpuMs, 0.0);
    EXPECT_LE(t[0].gpuMs, wallMs);
  }
  size_t bad = 0;
  for (size_t i = 0; i < n; ++i) {
    bool ok = std::abs(p[4 * i] - pos[4 * i]) <= 1e-6f && std::abs(p[4 * i + 1] - pos[4 * i + 1]) <= 1e-6f &&
              std::abs(p[4 * i + 2] - pos[4 * i + 2]) <= 1e-6f && p[4 * i + 3] == 1.0f && m[4 * i + 2] == 1.0f;
    if (!ok && bad++ < 5) ADD_FAILURE() << "vertex " << i << " of " << n << " not written or wrong";
  }
  EXPECT_EQ(bad, 0u);
  for (BufferId id : {in, out}) b.destroyBuffer(id);
}

// A buffer destroyed while work that uses it is pending lives until that work has run.
TEST_P(BackendContract, DestroyedBufferOutlivesPendingWork) {
  Backend& b = backend();
  ClassicJob<float> job(b, 256, 256);
  BufferId scratch = b.createBuffer(2 * job.bytes());
  b.upload(scratch, 0, job.vertices().data(), 2 * job.bytes());
  job.dispatch({}, 0, 256, scratch, job.vertOut);
  b.destroyBuffer(scratch);
  job.expectIdentity(0, 256, 256, 1e-6);
}

// The strict variants give the CPU backend's bits (the C++ twins, -ffp-contract=off).
TEST_P(BackendContract, StrictVariantsGiveTheCpuBackendsBits) {
  Backend& b = backend();
  HandLattice<double> L(true);
  PackedLattice P;
  P.params = L.params;
  P.frame = L.frame;
  P.coeffs = L.coeffs;
  std::vector<double> pos, nrm;
  makeVertices<double>(500, 400, pos, nrm, 11);
  Mesh mesh;
  for (size_t i = 0; i < 500; ++i) {
    mesh.positions.push_back({pos[4 * i], pos[4 * i + 1], pos[4 * i + 2]});
    mesh.normals.push_back({nrm[4 * i], nrm[4 * i + 1], nrm[4 * i + 2]});
  }
  for (bool f64 : {false, true}) {
    if (f64 && !b.info().limits.float64) continue;
    KernelVariant v{true, f64};
    ClassicOutput out = classicFfd(b, mesh, P, v), ref = classicFfd(sffd::testing::cpuBackend(), mesh, P, v);
    EXPECT_EQ(std::memcmp(out.positions.data(), ref.positions.data(), out.positions.size() * 8), 0) << "f64 " << f64;
    EXPECT_EQ(std::memcmp(out.normals.data(), ref.normals.data(), out.normals.size() * 8), 0) << "f64 " << f64;
  }
}

std::vector<std::string> contractBackends() {
  std::vector<std::string> names = {"vulkan", "vulkan-staging", "gl-egl", "gl-osmesa", "gles", "cpu"};
  return names;
}

INSTANTIATE_TEST_SUITE_P(Backends, BackendContract, ::testing::ValuesIn(contractBackends()),
                         [](const auto& info) { return sffd::testing::backendTestName(info.param); });

}  // namespace
}  // namespace sffd
