// Tests of the OpenGL compute driver and its context providers (EGL surfaceless, OSMesa, GLFW) on
// Mesa's llvmpipe. No X display is needed except for the GLFW test, which is skipped without one.
// What every backend must do is checked in ../backend_contract_test.cc.
#include <dlfcn.h>
#include <glad/gl.h>
#include <gtest/gtest.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <sffd/error.h>
#include "backends/classic_test_inputs.h"
#include "backends/opengl/gl_backend.h"
#include "backends/opengl/gl_context.h"
#include "kernels/common/shader_layout.h"

namespace sffd::gl {
namespace {

// Software devices only, as ctest runs them (set before any GL library is opened).
const bool kSoftware = [] {
  setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
  return true;
}();

std::unique_ptr<Backend> open(Provider p) {
  Options o;
  o.provider = p;
  return createBackend(o);
}

// Skips when the provider's library is missing on this machine (OSMesa is gone from Mesa 25.1).
#define SKIP_WITHOUT(provider)                                                                  \
  do {                                                                                          \
    if (!providerLibraryPresent(provider))                                                      \
      GTEST_SKIP() << providerName(provider) << " library not installed";                       \
  } while (0)

using sffd::testing::HandLattice;
using sffd::testing::makeVertices;

template <class Real>
struct ClassicRun {
  std::vector<Real> pos, nrm;
  std::vector<DispatchTiming> timings;
  double wallMs = 0;   // from the dispatch to the end of the downloads
  uint32_t groups[3] = {1, 1, 1};
};

// One classic_ffd dispatch over all vertices (gridFor splits it into a 2-D grid when needed).
template <class Real>
ClassicRun<Real> runClassic(Backend& b, KernelVariant v, const HandLattice<Real>& L, const std::vector<Real>& pos,
                            const std::vector<Real>& nrm) {
  const size_t n = pos.size() / 4, bytes = pos.size() * sizeof(Real);
  BufferId frame = b.createBuffer(L.frame.size() * sizeof(Real));
  BufferId coeffs = b.createBuffer(L.coeffs.size() * sizeof(Real));
  BufferId io[2];   // positions, then normals from element n
  for (BufferId& id : io) id = b.createBuffer(2 * bytes);
  b.upload(frame, 0, L.frame.data(), L.frame.size() * sizeof(Real));
  b.upload(coeffs, 0, L.coeffs.data(), L.coeffs.size() * sizeof(Real));
  b.upload(io[0], 0, pos.data(), bytes);
  b.upload(io[0], bytes, nrm.data(), bytes);

  gpu::ClassicParams params;
  params.lattice = L.params;
  params.range = {0, uint32_t(n), uint32_t(n), 0};
  Dispatch d;
  d.kernel = "classic_ffd";
  d.variant = v;
  d.params = &params;
  d.paramsSize = sizeof(params);
  d.buffers = {{SFFD_BINDING_LATTICE_COEFFS, coeffs}, {SFFD_BINDING_LATTICE_FRAME, frame},
               {SFFD_BINDING_CLASSIC_IN, io[0]}, {SFFD_BINDING_CLASSIC_OUT, io[1]}};
  d.label = "classic test";
  ClassicRun<Real> r;
  gridFor(n, b.info().limits, d.groups);
  std::memcpy(r.groups, d.groups, sizeof r.groups);
  auto t0 = std::chrono::steady_clock::now();
  b.dispatch(d);
  b.barrier();
  r.pos.resize(pos.size());
  r.nrm.resize(nrm.size());
  b.download(io[1], 0, r.pos.data(), bytes);
  b.download(io[1], bytes, r.nrm.data(), bytes);
  b.finish();
  r.wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  r.timings = b.takeTimings();
  for (BufferId id : io) b.destroyBuffer(id);
  b.destroyBuffer(frame);
  b.destroyBuffer(coeffs);
  return r;
}

// The identity lattice maps every point to itself (inside: w = 1, outside: extrapolated, w = 0)
// and keeps every normal.
template <class Real>
void expectIdentity(Backend& b, KernelVariant v, double tol) {
  HandLattice<Real> L;
  std::vector<Real> pos, nrm;
  makeVertices<Real>(1000, 900, pos, nrm);
  ClassicRun<Real> r = runClassic(b, v, L, pos, nrm);
  size_t bad = 0;
  for (size_t i = 0; i < pos.size() / 4 && bad < 10; ++i) {
    bool inside = i < 900;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(double(r.pos[4 * i + k]) - double(pos[4 * i + k])) > tol ||
          std::abs(double(r.nrm[4 * i + k]) - double(nrm[4 * i + k])) > tol) {
        ++bad;
        ADD_FAILURE() << "vertex " << i << " axis " << k << ": position " << r.pos[4 * i + k] << " vs "
                      << pos[4 * i + k] << ", normal " << r.nrm[4 * i + k] << " vs " << nrm[4 * i + k];
      }
    }
    EXPECT_EQ(double(r.pos[4 * i + 3]), inside ? 1.0 : 0.0) << "vertex " << i;
    EXPECT_EQ(double(r.nrm[4 * i + 3]), 0.0) << "vertex " << i;
  }
  ASSERT_EQ(r.timings.size(), 1u);
  EXPECT_EQ(r.timings[0].label, "classic test");
  if (b.info().limits.timestamps) {
    EXPECT_GE(r.timings[0].gpuMs, 0.0);
  }
}

class GlProviderTest : public ::testing::TestWithParam<Provider> {
 protected:
  void SetUp() override { SKIP_WITHOUT(GetParam()); }
};

TEST_P(GlProviderTest, ContextIsCore43AndInfoIsFilled) {
  auto b = open(GetParam());
  const DeviceInfo& info = b->info();
  EXPECT_EQ(info.api, "gl");
  EXPECT_EQ(info.provider, providerName(GetParam()));
  EXPECT_FALSE(info.name.empty());
  int major = 0, minor = 0;
  ASSERT_EQ(std::sscanf(info.driver.c_str(), "%d.%d", &major, &minor), 2) << info.driver;
  EXPECT_GE(major * 10 + minor, 43) << info.driver;
  GLint profile = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);   // the backend's context is current after creation
  EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT) << info.driver;
  // llvmpipe (LIBGL_ALWAYS_SOFTWARE=1 where Mesa is the driver) is a CPU device; a GPU driver's is "other".
  EXPECT_EQ(info.type, info.name.find("llvmpipe") != std::string::npos ? "cpu" : "other") << info.name;
  EXPECT_GE(info.limits.maxStorageBufferRange, 16u << 20);
  EXPECT_GT(info.limits.storageOffsetAlignment, 0u);
  EXPECT_GE(info.limits.maxWorkGroupCount[0], 65535u);
  const char* vendor = reinterpret_cast<const char*>(glGetString(GL_VENDOR));
  EXPECT_EQ(info.limits.float64, !doublesLoseBits(vendor ? vendor : "")) << vendor;
  std::printf("%s: %s | %s | ssbo %llu B, align %llu, groups %u, timestamps %d\n", info.provider.c_str(),
              info.name.c_str(), info.driver.c_str(), (unsigned long long)info.limits.maxStorageBufferRange,
              (unsigned long long)info.limits.storageOffsetAlignment, info.limits.maxWorkGroupCount[0],
              int(info.limits.timestamps));
}

// A dispatch's time measures its work: OSMesa's timestamps came 70 ns apart around a 3 ms deform (its llvmpipe
// runs the dispatch at the next flush), so `sffd bench` gave 0.000 ms for every stage there.
TEST_P(GlProviderTest, ADispatchsTimeMeasuresItsWork) {
  auto b = open(GetParam());
  ASSERT_TRUE(b->info().limits.timestamps);
  HandLattice<float> L(true);
  std::vector<float> pos, nrm;
  makeVertices<float>(1 << 20, 1 << 19, pos, nrm);
  runClassic(*b, {true, false}, L, pos, nrm);   // the first dispatch of a context was timed right even there
  ClassicRun<float> r = runClassic(*b, {true, false}, L, pos, nrm);
  ASSERT_EQ(r.timings.size(), 1u);
  // At least a twentieth of the dispatch, its downloads and the wait: the kernel is most of that on every driver.
  EXPECT_GE(r.timings[0].gpuMs, 0.05 * r.wallMs) << "dispatch " << r.timings[0].gpuMs << " ms of " << r.wallMs << " ms";
}

INSTANTIATE_TEST_SUITE_P(Headless, GlProviderTest, ::testing::Values(Provider::EGL, Provider::OSMesa),
                         [](const ::testing::TestParamInfo<Provider>& i) {
                           return std::string(i.param == Provider::EGL ? "EGL" : "OSMesa");
                         });

template <class Real>
void expectBitIdenticalAcrossProviders(KernelVariant v) {
  HandLattice<Real> L(true);
  std::vector<Real> pos, nrm;
  makeVertices<Real>(2000, 1500, pos, nrm, 3);
  ClassicRun<Real> egl, osmesa;
  {
    auto b = open(Provider::EGL);
    egl = runClassic(*b, v, L, pos, nrm);
  }
  {
    auto b = open(Provider::OSMesa);
    osmesa = runClassic(*b, v, L, pos, nrm);
  }
  // The lattice is not the identity: outputs really moved.
  double moved = 0;
  for (size_t i = 0; i < pos.size(); ++i) moved = std::max(moved, std::abs(double(egl.pos[i]) - double(pos[i])));
  EXPECT_GT(moved, 0.01);
  bool same = std::memcmp(egl.pos.data(), osmesa.pos.data(), pos.size() * sizeof(Real)) == 0 &&
              std::memcmp(egl.nrm.data(), osmesa.nrm.data(), nrm.size() * sizeof(Real)) == 0;
  std::printf("%s-%s: EGL and OSMesa outputs %s\n", v.strict ? "strict" : "fast", v.f64 ? "f64" : "f32",
              same ? "bit-identical" : "differ");
  if (v.strict) {
    EXPECT_TRUE(same);   // fast variants: measured and printed only
  }
}

TEST(GlCrossProvider, StrictOutputsBitIdenticalEglVsOSMesa) {
  SKIP_WITHOUT(Provider::EGL);
  SKIP_WITHOUT(Provider::OSMesa);
  expectBitIdenticalAcrossProviders<float>({true, false});
  expectBitIdenticalAcrossProviders<double>({true, true});
  expectBitIdenticalAcrossProviders<float>({false, false});
  expectBitIdenticalAcrossProviders<double>({false, true});
}

TEST(GlCrossProvider, EglThenOSMesaThenEglInOneProcess) {
  SKIP_WITHOUT(Provider::EGL);
  SKIP_WITHOUT(Provider::OSMesa);
  for (Provider p : {Provider::EGL, Provider::OSMesa, Provider::EGL}) {
    auto b = open(p);
    EXPECT_EQ(b->info().provider, providerName(p));
    expectIdentity<float>(*b, {true, false}, 1e-6);
  }
}

TEST(GlCrossProvider, TwoLiveBackendsInterleaved) {
  // Both providers alive at once: every call switches the current context and reloads glad.
  SKIP_WITHOUT(Provider::EGL);
  SKIP_WITHOUT(Provider::OSMesa);
  auto egl = open(Provider::EGL);
  auto osmesa = open(Provider::OSMesa);
  BufferId a = egl->createBuffer(64), c = osmesa->createBuffer(64);
  std::vector<uint8_t> x(64, 1), y(64, 2), back(64);
  egl->upload(a, 0, x.data(), 64);
  osmesa->upload(c, 0, y.data(), 64);
  expectIdentity<float>(*egl, {true, false}, 1e-6);
  expectIdentity<double>(*osmesa, {true, true}, 1e-14);
  egl->download(a, 0, back.data(), 64);
  EXPECT_EQ(back, x);
  osmesa->download(c, 0, back.data(), 64);
  EXPECT_EQ(back, y);
  egl.reset();
  expectIdentity<float>(*osmesa, {false, false}, 1e-6);
}

TEST(GlCrossProvider, TwoEglBackendsAndAnOutsideContextSwitch) {
  // Two contexts of one provider share its EGL display; a context switch made behind sffd's back
  // (as a viewer's own code might) is noticed and undone.
  SKIP_WITHOUT(Provider::EGL);
  auto a = open(Provider::EGL);
  auto b = open(Provider::EGL);
  expectIdentity<float>(*a, {true, false}, 1e-6);
  expectIdentity<float>(*b, {true, false}, 1e-6);
  void* egl = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(egl, nullptr);
  using GetDisplay = void* (*)();
  using MakeCurrent = unsigned (*)(void*, void*, void*, void*);
  auto getDisplay = reinterpret_cast<GetDisplay>(dlsym(egl, "eglGetCurrentDisplay"));
  auto makeCurrent = reinterpret_cast<MakeCurrent>(dlsym(egl, "eglMakeCurrent"));
  ASSERT_TRUE(getDisplay && makeCurrent);
  void* dpy = getDisplay();
  ASSERT_NE(dpy, nullptr);
  ASSERT_TRUE(makeCurrent(dpy, nullptr, nullptr, nullptr));   // nothing current any more
  expectIdentity<float>(*b, {false, false}, 1e-6);
  a.reset();   // the display stays initialised for b
  if (b->info().limits.float64) expectIdentity<double>(*b, {true, true}, 1e-14);
}

// NVIDIA's GL compiler rounds the doubles of a kernel's indexed local arrays to float (the H200, driver
// 580: classic FFD of the identity lattice 1.6e-9 off, PN records of 0.99 as 0.99000000953674316), so its
// GL devices report no float64 and a double request is refused; every other GL 4.3 driver keeps them.
TEST(GlDoubles, OnlyNvidiasGlDriverIsRefusedDoubles) {
  EXPECT_TRUE(doublesLoseBits("NVIDIA Corporation"));
  for (const char* vendor : {"Mesa", "Mesa/X.org", "AMD", "ATI Technologies Inc.", "Intel", "Intel Open Source Technology Center",
                             "VMware, Inc.", "Microsoft Corporation", "Qualcomm", ""})
    EXPECT_FALSE(doublesLoseBits(vendor)) << vendor;
}

// A buffer destroyed on a thread where the context cannot be made current (another thread holds it: the
// public API lets it go at the end of each call, a backend used directly does not) is deleted by the next
// call that makes it current, and nothing throws: destroyBuffer runs in destructors, which must not.
TEST(GlThreads, ABufferDestroyedWhereTheContextCannotBeCurrentIsDeletedLater) {
  SKIP_WITHOUT(Provider::EGL);
  auto b = open(Provider::EGL);   // current on this thread
  const BufferId id = b->createBuffer(64);
  const GLuint name = glBufferObject(*b, id);
  ASSERT_NE(name, 0u);
  std::thread([&] { EXPECT_NO_THROW(b->destroyBuffer(id)); }).join();
  EXPECT_EQ(glBufferObject(*b, id), 0u);
  EXPECT_TRUE(glIsBuffer(name));   // not deleted from the other thread
  b->finish();
  EXPECT_FALSE(glIsBuffer(name));
  b->endCall();   // now any thread may use it, one at a time
  std::thread([&] {
    expectIdentity<float>(*b, {true, false}, 1e-6);
    b.reset();
  }).join();
}

TEST(GlSelection, ListDevicesGivesEachHeadlessProvider) {
  auto devices = listDevices();
  ASSERT_FALSE(devices.empty());
  for (const DeviceInfo& d : devices) {
    EXPECT_EQ(d.api, "gl");
    EXPECT_TRUE(d.provider == "egl" || d.provider == "osmesa") << d.provider;
  }
  if (providerLibraryPresent(Provider::EGL) && providerLibraryPresent(Provider::OSMesa)) {
    ASSERT_EQ(devices.size(), 2u);
    EXPECT_EQ(devices[0].provider, "egl");
    EXPECT_EQ(devices[1].provider, "osmesa");
  }
}

TEST(GlSelection, AutoPrefersEglAndEnvironmentOverrides) {
  SKIP_WITHOUT(Provider::EGL);
  SKIP_WITHOUT(Provider::OSMesa);
  unsetenv("SFFD_GL_PROVIDER");
  EXPECT_EQ(open(Provider::Auto)->info().provider, "egl");
  setenv("SFFD_GL_PROVIDER", "osmesa", 1);
  EXPECT_EQ(open(Provider::Auto)->info().provider, "osmesa");
  EXPECT_EQ(open(Provider::EGL)->info().provider, "egl");   // only Auto is overridden
  setenv("SFFD_GL_PROVIDER", "vulkan", 1);
  try {
    open(Provider::Auto);
    ADD_FAILURE() << "unknown provider accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input) << e.what();
  }
  unsetenv("SFFD_GL_PROVIDER");
}

TEST(GlSelection, DeviceSubstringIsCheckedCaseInsensitively) {
  SKIP_WITHOUT(Provider::EGL);
  Options o;
  o.provider = Provider::EGL;
  o.deviceSubstring = createBackend(o)->info().name;   // the renderer here, in the other case
  for (char& c : o.deviceSubstring) c = std::isupper(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : char(std::toupper(c));
  EXPECT_EQ(createBackend(o)->info().provider, "egl") << o.deviceSubstring;
  o.deviceSubstring = "no such renderer";
  try {
    createBackend(o);
    ADD_FAILURE() << "mismatching renderer accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Device) << e.what();
  }
  o.provider = Provider::Auto;   // tries every headless provider, then fails as a device error
  try {
    createBackend(o);
    ADD_FAILURE() << "mismatching renderer accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Device) << e.what();
  }
}

TEST(GlGlfw, HiddenWindowContextRunsKernels) {
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display) GTEST_SKIP() << "DISPLAY is not set (run under xvfb-run -a)";
  auto b = open(Provider::GLFW);
  EXPECT_EQ(b->info().provider, "glfw");
  expectIdentity<float>(*b, {true, false}, 1e-6);
  expectIdentity<double>(*b, {true, true}, 1e-14);
  // A second window after the first is gone, and one next to an EGL backend.
  b.reset();
  auto again = open(Provider::GLFW);
  if (providerLibraryPresent(Provider::EGL)) {
    auto egl = open(Provider::EGL);
    expectIdentity<float>(*egl, {true, false}, 1e-6);
  }
  expectIdentity<float>(*again, {false, false}, 1e-6);
}

TEST(GlGlfw, NoDisplayIsADeviceError) {
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  std::string saved = display ? display : "", savedWayland = wayland ? wayland : "";
  unsetenv("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  try {
    open(Provider::GLFW);
    ADD_FAILURE() << "a GLFW context without a display";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Device) << e.what();
    EXPECT_NE(std::string(e.what()).find("glfw"), std::string::npos) << e.what();
  }
  if (!saved.empty()) setenv("DISPLAY", saved.c_str(), 1);
  if (!savedWayland.empty()) setenv("WAYLAND_DISPLAY", savedWayland.c_str(), 1);
}

}  // namespace
}  // namespace sffd::gl
