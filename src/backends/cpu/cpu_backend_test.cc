// What is particular to the CPU backend: every kernel has a CPU entry, neither the thread count nor the
// kernels' AVX2 copies change the bits, and a kernel's error on a worker thread comes back as an sffd::Error.
#include "backends/cpu/cpu_backend.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include <sffd/sffd.h>
#include "core/kernel_registry.h"
#include "kernels/pn/pn_triangles.h"
#include "pipelines/deform_session.h"

namespace sffd {
namespace {

TEST(CpuBackend, EveryKernelHasACpuEntry) {
  size_t n = 0;
  for (const EmbeddedKernel& k : embeddedKernels()) {
    const cpu::Kernel* entry = cpu::findKernel(k.name);
    ASSERT_NE(entry, nullptr) << k.name << " has no CPU entry (src/backends/cpu/cpu_kernels.cpp)";
    EXPECT_GT(entry->paramsSize, 0u) << k.name;
    ++n;
  }
  EXPECT_EQ(n, 10u);
  EXPECT_EQ(cpu::findKernel("no_such_kernel"), nullptr);
}

TEST(CpuBackend, ThreadCountDoesNotChangeTheBits) {
  Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
  Lattice L = makeIdentityLattice({-1.1, -1.1, -1.1}, {1.1, 1.1, 1.1}, {5, 5, 5}, {2, 2, 2});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (auto& p : L.controlPoints) p += glm::dvec3(u(rng), u(rng), u(rng));
  auto run = [&](const char* threads, bool split) {
    setenv("SFFD_CPU_THREADS", threads, 1);
    auto b = cpu::createBackend();
    EXPECT_NE(b->info().name.find(std::string("(") + threads + " threads"), std::string::npos) << b->info().name;
    DeformSessionOptions o;
    o.edgeLength = 0.1;
    o.level = 4;
    o.split = split;
    DeformSession s(*b, m, L, o);
    s.deform(L);
    unsetenv("SFFD_CPU_THREADS");
    return s.output().tess;
  };
  std::vector<double> one = run("1", false);
  EXPECT_EQ(run("3", false), one);
  EXPECT_EQ(run("2", true), one);
}

// Every kernel's AVX2 copy (withAvx2, cpu_kernel.h) against its baseline copy (SFFD_CPU_AVX2=0): every
// method in float and double, lattices of degree 2, 3 and mixed, levels 1, 6 and 11 (the tessellation's
// lanes: a tail alone, and full groups of eight with tails); the split run's steps have no AVX2 copies,
// its pn and clip do.
TEST(CpuBackend, Avx2CopiesGiveTheBitsOfTheBaseline) {
  unsetenv("SFFD_CPU_AVX2");
  if (!cpuUsesAvx2()) GTEST_SKIP() << "no AVX2 copies to compare: a sanitizer build, another processor, or no AVX2";
  const Mesh mesh = readMesh(std::string(SFFD_TEST_DATA) + "/torus.obj");
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.08, 0.08);
  for (std::array<int, 3> degree : {std::array{2, 2, 2}, std::array{3, 3, 3}, std::array{1, 2, 3}}) {
    Lattice lattice = fitLattice(mesh, {5, 5, 4}, degree);
    for (auto& p : lattice.controlPoints) p += glm::dvec3(u(rng), u(rng), u(rng));
    for (Method method : {Method::Smooth, Method::Accurate, Method::Classic})
      for (int variant = 0; variant < 3; ++variant) {
        DeformOptions o;
        o.method = method;
        o.edgeLength = 0.35;
        o.tess = 1 + 5 * variant;
        o.split = method == Method::Smooth && variant == 1;
        o.precision = variant == 2 ? Precision::Double : Precision::Float;
        auto run = [&](const char* avx2) {
          setenv("SFFD_CPU_AVX2", avx2, 1);
          DeviceRequest request;
          request.name = "cpu";
          Device cpu = Device::open(request);
          Deformer d(cpu, mesh, lattice, o);
          d.deform(lattice);
          Mesh r = d.result();
          unsetenv("SFFD_CPU_AVX2");
          return r;
        };
        const Mesh baseline = run("0"), avx2 = run("1");
        const std::string what = "degree " + std::to_string(degree[0]) + std::to_string(degree[2]) + ", method " + std::to_string(int(method)) +
                                 ", variant " + std::to_string(variant);
        ASSERT_EQ(baseline.positions.size(), avx2.positions.size()) << what;
        EXPECT_GT(baseline.positions.size(), 0u) << what;
        EXPECT_EQ(std::memcmp(baseline.positions.data(), avx2.positions.data(), avx2.positions.size() * sizeof(glm::dvec3)), 0)
            << what;
        EXPECT_EQ(std::memcmp(baseline.normals.data(), avx2.normals.data(), avx2.normals.size() * sizeof(glm::dvec3)), 0)
            << what;
      }
  }
}

TEST(CpuBackend, KernelErrorsOnWorkerThreadsAreInternalErrors) {
  setenv("SFFD_CPU_THREADS", "4", 1);
  auto b = cpu::createBackend();
  unsetenv("SFFD_CPU_THREADS");
  // 20000 triangles whose vertex ids run past the 3 vertices there are.
  const uint32_t nt = 20000;
  std::vector<float> verts(24, 0.0f), slots(48 * size_t(nt), 0.0f);
  std::vector<uint32_t> tris(8 * size_t(nt));
  for (uint32_t t = 0; t < nt; ++t) tris[8 * t] = t, tris[8 * t + 1] = 1, tris[8 * t + 2] = 2;
  auto make = [&](const void* data, size_t bytes) {
    BufferId id = b->createBuffer(bytes);
    b->upload(id, 0, data, bytes);
    return id;
  };
  BufferId vertices = make(verts.data(), verts.size() * 4);   // 3 positions, then 3 normals
  BufferId tri = make(tris.data(), tris.size() * 4), slot = make(slots.data(), slots.size() * 4);
  BufferId out = b->createBuffer(size_t(nt) * SFFD_PN_STRIDE * 16);
  gpu::PnParams params;
  params.range = {0, nt, 3, 0};
  Dispatch d;
  d.kernel = "pn_triangles";
  d.params = &params;
  d.paramsSize = sizeof params;
  d.buffers = {{SFFD_BINDING_MESH_VERTICES, vertices}, {SFFD_BINDING_MESH_TRIANGLES, tri},
               {SFFD_BINDING_MESH_SLOT_NORMALS, slot}, {SFFD_BINDING_PN_OUT, out}};
  gridFor(nt, b->info().limits, d.groups);
  try {
    b->dispatch(d);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Internal);
    EXPECT_NE(std::string(e.what()).find("vertex id"), std::string::npos) << e.what();
  }
  // The backend still works: the first three triangles are valid.
  params.range = {0, 3, 3, 0};
  gridFor(3, b->info().limits, d.groups);
  b->dispatch(d);
  EXPECT_EQ(b->takeTimings().size(), 1u);
}

}  // namespace
}  // namespace sffd
