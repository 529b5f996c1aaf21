// DeformSession (the device-resident path of deform, view and bench) on every backend, the CPU one
// included, against the stages run one by one on the CPU backend in the strict variant: bit-identical
// records and output, across re-deforms, chunking, the split kernels and knot-box clipping.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <set>
#include <sstream>
#include <tuple>

#include "backends/backend_select.h"
#include "backends/backend_test_support.h"
#include "model/mesh.h"
#include "pipelines/deform_session.h"
#include "pipelines/deform_session_internal.h"
#include "pipelines/device_reals.h"
#include "pipelines/patch_output.h"
#include <sffd/error.h>
#include "kernels/clip/knot_box_clip.h"
#include "model/lattice_pack.h"
#include "kernels/pn/pn_triangles.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/smooth/smooth_deform.h"
#include "kernels/clip/split_pattern_table.h"
#include "backends/vulkan/vk_backend.h"

using namespace sffd;

namespace {

// A lattice of counts^3 control points of `degree` around the mesh, each moved by up to `amount`.
Lattice jitteredLattice(const Mesh& m, int counts, int degree, unsigned seed, double amount) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::dvec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  Lattice L = makeIdentityLattice(lo - 0.01, hi + 0.01, {counts, counts, counts}, {degree, degree, degree});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (auto& p : L.controlPoints) p += glm::dvec3(u(rng), u(rng), u(rng));
  return L;
}

Lattice latticeFor(const Mesh& m, unsigned seed, double amount) { return jitteredLattice(m, 5, 2, seed, amount); }

// The whole smooth job stage by stage on the CPU backend, in the strict float order.
struct Reference {
  SubTriangleRecords subs;
  SmoothOutput out;
};
Reference reference(const Mesh& m, const Lattice& L, const DeformSessionOptions& o) {
  const KernelVariant strict{true, false};
  Backend& cpu = sffd::testing::cpuBackend();
  PreparedMesh P = prepareMesh(m);
  PnOutput pn = pnTriangles(cpu, P, strict);
  Reference r;
  r.subs = o.knotBoxClip ? recordsFromSubTriangles(P, pn, clipAgainstKnotBoxes(m, L), strict)
                         : regularClip(cpu, P, pn, buildClipTriangles(m, o.edgeLength, splitPatternTable().nmax()), o.edgeLength, strict);
  r.out = smoothDeform(cpu, packLattice(L), r.subs, makeFitTable(6), o.level, strict);
  return r;
}

class DeformSessionTest : public ::testing::TestWithParam<std::string> {};

TEST_P(DeformSessionTest, StrictSessionEqualsCpuReferenceAcrossRedeforms) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  for (auto [file, l] : {std::pair{"/cube2.obj", 0.5}, std::pair{"/torus.obj", 0.05}}) {
    SCOPED_TRACE(file);
    Mesh m = readMesh(std::string(SFFD_TEST_DATA) + file);
    Lattice A = latticeFor(m, 1, 0.1), B = latticeFor(m, 2, 0.2);
    DeformSessionOptions o;
    o.variant = {true, false};
    o.edgeLength = l;
    o.level = 4;
    DeformSession s(*b.backend, m, A, o);
    Reference ra = reference(m, A, o), rb = reference(m, B, o);
    ASSERT_EQ(s.subTriangles(), ra.subs.size());
    SubTriangleRecords recs = s.records();
    EXPECT_EQ(recs.headers, ra.subs.headers);
    EXPECT_EQ(recs.records, ra.subs.records);
    s.deform(A);
    SmoothOutput a1 = s.output();
    EXPECT_EQ(a1.patches, ra.out.patches);
    EXPECT_EQ(a1.tess, ra.out.tess);
    s.deform(B);
    EXPECT_EQ(s.output().tess, rb.out.tess);
    s.deform(A);
    EXPECT_EQ(s.output().tess, a1.tess);
    EXPECT_GT(s.timings().deformMs, 0.0);
    s.precompute();   // again: the same records
    EXPECT_EQ(s.records().records, ra.subs.records);
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

TEST_P(DeformSessionTest, ChunkedSplitAndKnotBoxSessionsEqualCpuReference) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
  Lattice A = latticeFor(m, 3, 0.15);
  DeformSessionOptions o;
  o.variant = {true, false};
  o.edgeLength = 0.3;
  o.level = 3;
  Reference ra = reference(m, A, o);
  o.maxChunkSubTriangles = 97;
  {
    DeformSession s(*b.backend, m, A, o);
    EXPECT_GT(s.chunks().size(), 2u);
    s.deform(A);
    EXPECT_EQ(s.output().tess, ra.out.tess);
  }
  o.maxChunkSubTriangles = 0;
  o.split = true;
  {
    DeformSession s(*b.backend, m, A, o);
    const SessionTimings& t = s.deform(A);
    EXPECT_EQ(t.dispatches.size(), 4u);
    EXPECT_EQ(s.output().patches, ra.out.patches);
  }
  o.split = false;
  o.knotBoxClip = true;
  Reference rk = reference(m, A, o);
  DeformSession k(*b.backend, m, A, o);
  k.deform(A);
  EXPECT_EQ(k.subTriangles(), rk.subs.size());
  EXPECT_EQ(k.output().tess, rk.out.tess);
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

// The pre-compute in chunks of a few mesh triangles (the path of a mesh beyond one storage binding):
// the same records and output as in one chunk, with pre-split parents (cube2 at a short edge length),
// sub-triangle chunks across the pre-compute's, a repeated precompute, and knot-box clipping.
TEST_P(DeformSessionTest, PrecomputeChunksGiveTheSameRecordsAndOutput) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  for (auto [file, l] : {std::pair{"/cube2.obj", 0.05}, std::pair{"/sphere.obj", 0.3}}) {
    for (bool knotBox : {false, true}) {
      SCOPED_TRACE(std::string(file) + (knotBox ? " knot-box" : " regular"));
      Mesh m = readMesh(std::string(SFFD_TEST_DATA) + file);
      Lattice A = latticeFor(m, 5, 0.1);
      DeformSessionOptions o;
      o.variant = {true, false};
      o.edgeLength = l;
      o.level = 3;
      o.knotBoxClip = knotBox;
      DeformSession one(*b.backend, m, A, o);
      ASSERT_EQ(one.precomputeChunks(), 1u);
      one.deform(A);
      o.maxChunkParents = 5;
      o.maxChunkSubTriangles = 50;
      DeformSession many(*b.backend, m, A, o);
      EXPECT_GT(many.precomputeChunks(), 2u);
      many.precompute();
      many.deform(A);
      SubTriangleRecords r1 = one.records(), r2 = many.records();
      EXPECT_EQ(r2.headers, r1.headers);
      EXPECT_EQ(r2.records, r1.records);
      SmoothOutput o1 = one.output(), o2 = many.output();
      EXPECT_EQ(o2.tess, o1.tess);
      EXPECT_EQ(o2.patches, o1.patches);
    }
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

// A one-shot session (DeformSessionOptions::once) makes its clip triangles and runs every stage a few
// parents at a time (streamChunks): in many small chunks, with pre-split parents (cube2 at l = 0.05) and
// with knot-box clipping, the same pre-images, tessellation and patches as a session that keeps everything.
// A strip of 40 triangles that widen along it (0.01 to 1.9): at l = 0.05 the last are split into several clip
// triangles each, so a streamed job's later chunks need larger buffers than its first, which StreamBuffer::atLeast
// makes again (the split-pattern table and the vertex section uploaded into the new ones).
Mesh wideningStrip() {
  Mesh m;
  double x = 0, w = 0.01;
  for (int i = 0; i <= 20; ++i, x += w, w *= 1.3) m.positions.insert(m.positions.end(), {{x, 0, 0}, {x, 0.3, 0.05 * x}});
  for (uint32_t i = 0; i < 20; ++i)
    m.triangles.insert(m.triangles.end(), {{2 * i, 2 * i + 2, 2 * i + 1}, {2 * i + 1, 2 * i + 2, 2 * i + 3}});
  for (uint32_t v = 0; v < m.positions.size(); ++v) m.weldId.push_back(v);
  computeVertexNormals(m);
  return m;
}

TEST_P(DeformSessionTest, StreamedChunksGiveTheSameOutput) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  for (auto [file, l, knotBox] : {std::tuple{"/cube2.obj", 0.05, false}, std::tuple{"/sphere.obj", 0.3, false},
                                  std::tuple{"/sphere.obj", 0.3, true}, std::tuple{"/torus.obj", 0.3, true},
                                  std::tuple{"widening strip", 0.05, false}}) {
    SCOPED_TRACE(std::string(file) + (knotBox ? " knot-box" : ""));
    const Mesh m = file[0] == '/' ? readMesh(std::string(SFFD_TEST_DATA) + file) : wideningStrip();
    const Lattice A = latticeFor(m, 5, 0.1);
    DeformSessionOptions o;
    o.variant = {true, false};
    o.edgeLength = l;
    o.level = 3;
    o.knotBoxClip = knotBox;
    DeformSession one(*b.backend, m, A, o);
    one.deform(A);
    const SmoothOutput want = one.output();
    const SubTrianglePreImages wantPre = one.preImages();
    o.once = true;
    o.maxChunkParents = 5;
    o.maxChunkSubTriangles = 50;
    DeformSession streamed(*b.backend, m, A, o);
    ASSERT_TRUE(streamed.streamed());
    EXPECT_TRUE(streamed.chunks().empty());
    streamed.deform(A);
    SmoothOutput got;
    SubTrianglePreImages gotPre;
    size_t chunks = 0;
    const size_t tessReals = 2 * size_t(tessVertexCount(o.level)) * 4, patchReals = SFFD_PATCH_STRIDE * 4;
    streamed.streamChunks([&](const DeformSession::Chunk& c, const SubTrianglePreImages& pre) {
      EXPECT_EQ(c.first, gotPre.size());
      ASSERT_EQ(pre.size(), c.count);
      gotPre.parent.insert(gotPre.parent.end(), pre.parent.begin(), pre.parent.end());
      gotPre.lam.insert(gotPre.lam.end(), pre.lam.begin(), pre.lam.end());
      const std::vector<double> tess = downloadReals(*b.backend, c.output, 0, c.count * tessReals, false);
      const std::vector<double> patches = downloadReals(*b.backend, c.output, c.patchesOffset, c.count * patchReals, false);
      got.tess.insert(got.tess.end(), tess.begin(), tess.end());
      got.patches.insert(got.patches.end(), patches.begin(), patches.end());
      ++chunks;
    });
    EXPECT_GT(chunks, 5u);
    EXPECT_EQ(streamed.subTriangles(), one.subTriangles());
    EXPECT_EQ(gotPre.parent, wantPre.parent);
    EXPECT_EQ(gotPre.lam, wantPre.lam);
    EXPECT_EQ(got.tess, want.tess);
    EXPECT_EQ(got.patches, want.patches);
    // Once: what a repeated or kept job reads is gone.
    EXPECT_THROW(streamed.streamChunks([](const DeformSession::Chunk&, const SubTrianglePreImages&) {}), Error);
    EXPECT_THROW(streamed.deform(A), Error);
    EXPECT_THROW(streamed.records(), Error);
    EXPECT_THROW(streamed.output(), Error);
    EXPECT_THROW(streamed.precompute(), Error);
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

// A lattice too large for the deform kernels' parameter block is read from the storage buffers:
// the same bits.
TEST_P(DeformSessionTest, LatticeTooLargeToInlineGivesTheSameOutput) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
  Lattice big = jitteredLattice(m, 12, 2, 7, 0.03);
  ASSERT_EQ(deformParamsFor(packLattice(big), false).lattice.break_offset.w, 0u) << "the lattice should not fit inline";
  DeformSessionOptions o;
  o.variant = {true, false};
  o.edgeLength = 0.3;
  o.level = 3;
  DeformSession s(*b.backend, m, big, o);
  s.deform(big);
  EXPECT_EQ(s.output().tess, reference(m, big, o).out.tess);
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

// A backend that forwards to another, with its kernels compiled to assume nothing about the lattice
// (KernelVariant::assumptions = 0: the run-time branches of lattice_eval.glsl and smooth_deform.glsl,
// the path of a caller that states nothing) and, optionally, a smaller storage binding.
class ForwardingBackend final : public Backend {
 public:
  ForwardingBackend(Backend& to, uint64_t maxStorageBufferRange = 0) : to_(to), info_(to.info()) {
    if (maxStorageBufferRange) info_.limits.maxStorageBufferRange = maxStorageBufferRange;
  }
  const DeviceInfo& info() const override { return info_; }
  BufferId createBuffer(uint64_t bytes) override { return to_.createBuffer(bytes); }
  void destroyBuffer(BufferId b) override { to_.destroyBuffer(b); }
  void upload(BufferId b, uint64_t offset, const void* data, uint64_t bytes) override { to_.upload(b, offset, data, bytes); }
  void download(BufferId b, uint64_t offset, void* data, uint64_t bytes) override { to_.download(b, offset, data, bytes); }
  void dispatch(const Dispatch& d) override {
    Dispatch plain = d;
    assumed |= d.variant.assumptions;
    dispatched.insert(useOf(d.kernel, d.variant));
    plain.variant.assumptions = 0;
    to_.dispatch(plain);
  }
  void precompile(const std::vector<KernelUse>& kernels) override {
    for (const KernelUse& k : kernels) precompiled.insert(useOf(k.kernel, k.variant));
  }
  void barrier() override { to_.barrier(); }
  void finish() override { to_.finish(); }
  std::vector<DispatchTiming> takeTimings() override { return to_.takeTimings(); }
  uint32_t assumed = 0;   // the assumptions the session asked for, taken away
  // The kernel variants asked for ahead and those dispatched (name, strict, f64, assumptions).
  using Use = std::tuple<std::string, bool, bool, uint32_t>;
  static Use useOf(std::string_view kernel, KernelVariant v) { return {std::string(kernel), v.strict, v.f64, v.assumptions}; }
  std::set<Use> precompiled, dispatched;

 private:
  Backend& to_;
  DeviceInfo info_;
};

// Kernels compiled with no assumptions give the bits of those compiled for their lattice: degree 2
// inline, degree 3, a lattice read from the storage buffers, the split kernels.
TEST_P(DeformSessionTest, KernelsWithoutLatticeAssumptionsGiveTheSameBits) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  ForwardingBackend plain(*b.backend);
  Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
  for (auto [counts, degree, split] : {std::tuple{5, 2, false}, std::tuple{6, 3, true}, std::tuple{12, 2, false}}) {
    SCOPED_TRACE(std::to_string(counts) + "^3 of degree " + std::to_string(degree) + (split ? ", split" : ""));
    Lattice L = jitteredLattice(m, counts, degree, unsigned(counts), 0.05);
    DeformSessionOptions o;
    o.variant = {true, false};
    o.edgeLength = 0.3;
    o.level = 2;
    o.split = split;
    DeformSession assumed(*b.backend, m, L, o), none(plain, m, L, o);
    assumed.deform(L);
    none.deform(L);
    EXPECT_NE(plain.assumed, 0u) << "the deform kernels should state their assumptions";
    SmoothOutput a = assumed.output(), n = none.output();
    EXPECT_EQ(n.tess, a.tess);
    EXPECT_EQ(n.patches, a.patches);
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

// A session asks ahead (Backend::precompile) for exactly the kernel variants it dispatches: regular and
// knot-box clipping, fused and split deform, kept and one-shot (streamed). The same on every backend:
// on the CPU device, which takes no time to compile the variants without assumptions.
TEST(DeformSessionKernels, PrecompilesWhatItDispatches) {
  Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
  Lattice L = latticeFor(m, 1, 0.1);
  for (auto [knotBox, split, once] : {std::tuple{false, false, false}, std::tuple{true, false, false},
                                      std::tuple{false, true, false}, std::tuple{false, false, true}, std::tuple{true, true, true}}) {
    SCOPED_TRACE(std::string(knotBox ? "knot-box" : "regular") + (split ? ", split" : "") + (once ? ", one-shot" : ""));
    ForwardingBackend recorded(sffd::testing::cpuBackend());
    DeformSessionOptions o;
    o.edgeLength = 0.3;
    o.level = 2;
    o.knotBoxClip = knotBox;
    o.split = split;
    o.once = once;
    DeformSession s(recorded, m, L, o);
    s.deform(L);
    if (once) s.streamChunks([](const DeformSession::Chunk&, const SubTrianglePreImages&) {});
    EXPECT_FALSE(recorded.dispatched.empty());
    EXPECT_EQ(recorded.precompiled, recorded.dispatched);
    // A small one-shot job asks for deform_smooth's one-site form (deformVariantOf; forDevice keeps it on lavapipe 22.3).
    for (const auto& [kernel, strict, f64, assumptions] : recorded.dispatched) {
      if (kernel == "deform_smooth") {
        EXPECT_EQ((assumptions & SFFD_ASSUME_ONE_SAMPLE_SITE) != 0, once && !split) << assumptions;
      }
    }
  }
}

// deform_smooth's one-site form only for a one-shot, fused job of at most kOneSampleSiteMaxSubTriangles estimated
// sub-triangles: one triangle of side 100 at l = 1 has about 10,000, at l = 0.5 about 40,000.
TEST(DeformSessionKernels, OneSampleSiteOnlyForSmallOneShotJobs) {
  Mesh m;
  m.positions = {{0, 0, 0}, {100, 0, 0}, {50, 50 * std::sqrt(3.0), 0}};
  m.triangles = {{0, 1, 2}};
  auto asks = [&](bool once, bool split, double l) {
    DeformSessionOptions o;
    o.once = once, o.split = split, o.edgeLength = l;
    return (deformVariantOf(o, m).assumptions & SFFD_ASSUME_ONE_SAMPLE_SITE) != 0;
  };
  EXPECT_TRUE(asks(true, false, 1.0));
  EXPECT_FALSE(asks(true, false, 0.5));
  EXPECT_FALSE(asks(false, false, 1.0));
  EXPECT_FALSE(asks(true, true, 1.0));
}

// A device whose storage binding cannot hold the job's vertices and one triangle's pre-compute inputs:
// an input error that says so.
TEST_P(DeformSessionTest, RefusesVerticesBeyondOneStorageBinding) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  ForwardingBackend small(*b.backend, 4096);
  Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
  Lattice A = latticeFor(m, 1, 0.1);
  DeformSessionOptions o;
  o.edgeLength = 0.3;
  try {
    DeformSession s(small, m, A, o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
    EXPECT_NE(std::string(e.what()).find("exceed one storage binding"), std::string::npos) << e.what();
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

TEST_P(DeformSessionTest, RefusesALatticeOfAnotherStructureAndBadOptions) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/cube2.obj");
  Lattice A = latticeFor(m, 1, 0.1);
  DeformSession s(*b.backend, m, A, {});
  Lattice other = makeIdentityLattice({-1, -1, -1}, {1, 1, 1}, {4, 5, 5}, {2, 2, 2});
  try {
    s.deform(other);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
  }
  DeformSessionOptions bad;
  bad.edgeLength = 0;
  EXPECT_THROW(DeformSession(*b.backend, m, A, bad), Error);
  bad.edgeLength = 0.2;
  bad.level = 65;
  EXPECT_THROW(DeformSession(*b.backend, m, A, bad), Error);
}

// Vulkan through staging memory, as on a discrete GPU (SFFD_VK_STAGING=1): once warm, a lattice edit (deform,
// output) and a repeated pre-compute allocate no device memory (each allocation costs a discrete GPU's driver
// a fraction of a millisecond; uploads staged through memory of their own did), and a streamed one-shot job
// keeps its buffers from chunk to chunk instead of making five a chunk.
TEST(DeformSessionVulkan, WarmEditsAndStreamedChunksAllocateNoDeviceMemory) {
  setenv("SFFD_VK_STAGING", "1", 1);   // read when the device is created
  std::string why;
  auto opened = sffd::testing::openUnlessAbsent("vulkan", sffd::testing::openForTest, why);
  unsetenv("SFFD_VK_STAGING");
  if (!opened) GTEST_SKIP() << why;
  Backend& b = *opened->backend;
  const Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/torus.obj");
  const Lattice A = latticeFor(m, 1, 0.1), B = latticeFor(m, 2, 0.2);
  DeformSessionOptions o;
  o.edgeLength = 0.1;
  o.level = 4;
  {
    DeformSession s(b, m, A, o);
    s.deform(A);
    const SmoothOutput a = s.output();
    const size_t warm = vk::deviceMemoryAllocations();
    s.deform(B);
    EXPECT_NE(s.output().tess, a.tess);
    s.precompute();
    s.deform(A);
    EXPECT_EQ(s.output().tess, a.tess);
    EXPECT_EQ(vk::deviceMemoryAllocations(), warm);
  }
  o.once = true;
  o.maxChunkParents = 20;
  DeformSession streamed(b, m, A, o);
  streamed.deform(A);
  const size_t before = vk::deviceMemoryAllocations();
  size_t chunks = 0;
  streamed.streamChunks([&](const DeformSession::Chunk&, const SubTrianglePreImages&) { ++chunks; });
  EXPECT_GT(chunks, 20u);
  EXPECT_LT(vk::deviceMemoryAllocations() - before, chunks / 2);
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Backends, DeformSessionTest, ::testing::ValuesIn(sffd::testing::testBackends()),
                         [](const auto& info) { return sffd::testing::backendTestName(info.param); });

}  // namespace
