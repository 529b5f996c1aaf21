// The host-memory estimate of a streamed smooth or one-shot accurate job (stream_budget.h): its
// sub-triangle bound holds for every clipping, only a streamed job gets it, the accurate front counts where
// the patches lie, and a one-shot result() is still checked against the whole job's. That it bounds the
// peak RSS: MemoryLimit.StreamedEstimateBoundsThePeak, AccurateOneShotEstimateBoundsThePeak (tests/).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include <sffd/sffd.h>

#include "backends/backend_test_support.h"
#include "core/job_budget.h"
#include "pipelines/deform_session.h"
#include "pipelines/deformer_internal.h"
#include "pipelines/stream_budget.h"

using namespace sffd;

namespace {

Mesh testMesh(const std::string& name) { return readMesh(std::string(SFFD_TEST_DATA) + "/" + name); }

Lattice twisted(const Mesh& m) {
  Lattice L = fitLattice(m, {5, 5, 5}, {2, 2, 2});
  applyLatticePreset(L, "twist", 0.3);
  return L;
}

Device cpuDevice() {
  DeviceRequest r;
  r.name = "cpu";
  return Device::open(r);
}

struct NullSink final : MeshSink {
  void add(const Mesh&, size_t) override {}
};

// Per parent c^2 sub-triangles for c segments on its longest edge (2c^2 pre-split): never fewer than the
// clipping makes, and close enough to budget by, from one sub-triangle a parent to pre-split parents.
TEST(StreamBudget, SubTriangleBoundHoldsForEveryEdgeLength) {
  Backend& cpu = sffd::testing::cpuBackend();
  for (const char* name : {"sphere.obj", "torus.obj", "cube.obj", "teapot_8x8.obj"})
    for (double fraction : {1.0, 0.25, 0.08}) {   // of the default edge length; 0.08 pre-splits the cube's faces
      const Mesh m = testMesh(name);
      DeformSessionOptions o;
      o.edgeLength = fraction * defaultEdgeLength(m);
      o.level = 1;
      DeformSession session(cpu, m, twisted(m), o);
      const double made = double(session.subTriangles());
      const StreamShape shape = streamShape(m, o.edgeLength, 1, 1000);
      EXPECT_GE(shape.subTriangles, made) << name << " " << fraction;
      EXPECT_LE(shape.subTriangles, 4 * made) << name << " " << fraction;
      EXPECT_LE(shape.chunkSubTriangles, shape.subTriangles) << name;
    }
}

// Only a one-shot job with regular clipping streams: the others keep the whole job's estimate.
TEST(StreamBudget, OnlyStreamedJobsGetTheStreamedEstimate) {
  Device device = cpuDevice();
  const Mesh sphere = testMesh("sphere.obj");
  const Lattice lattice = twisted(sphere);
  auto made = [&](DeformOptions o) {
    o.tess = 3;
    return std::make_unique<Deformer>(device, sphere, lattice, o);
  };
  const auto plain = made({});
  const Deformer::Impl& I = plain->internal();
  const JobEstimate whole = estimateSmoothJob(I.input, estimateSubTriangles(I.input, I.resolved.edgeLength), 3, 4, true);
  const uint64_t wholeBytes = whole.hostBytes + estimateLatticeBytes(lattice);
  ASSERT_TRUE(I.estimate);
  EXPECT_EQ(I.estimate->hostBytes, wholeBytes);
  EXPECT_FALSE(I.wholeEstimate);

  DeformOptions knotBox;
  knotBox.once = true;
  knotBox.clip = Clip::KnotBox;
  const auto clipped = made(knotBox);
  EXPECT_EQ(clipped->internal().estimate->hostBytes, wholeBytes);
  EXPECT_FALSE(clipped->internal().wholeEstimate);

  DeformOptions once;
  once.once = true;
  const auto streamed = made(once);
  const Deformer::Impl& S = streamed->internal();
  ASSERT_TRUE(S.estimate && S.wholeEstimate);
  EXPECT_EQ(S.wholeEstimate->hostBytes, wholeBytes);
  const JobEstimate own = estimateStreamedSmoothJob(S.input, sessionOptionsOf(S.resolved), device.info(), meshHeldBytes(sphere));
  EXPECT_EQ(S.estimate->hostBytes, own.hostBytes + estimateLatticeBytes(lattice));
  EXPECT_GE(S.estimate->outputVertices, 2040u * 10u);   // every patch vertex of 2,040 patches of level 3

  // Accurate: its run's estimate (deformer_accurate.cpp), a kept Deformer's the whole job's, a one-shot one's
  // from what stays alive (below the whole job's where the output is large: MemoryLimit.AccurateOneShot*),
  // with the caller's mesh, the lattice and the device's buffers in host memory.
  DeformOptions accurate;
  accurate.method = Method::Accurate;
  const auto kept = made(accurate);
  ASSERT_TRUE(kept->internal().estimate);
  EXPECT_FALSE(kept->internal().wholeEstimate);
  accurate.once = true;
  const auto oneShot = made(accurate);
  const Deformer::Impl& A = oneShot->internal();
  ASSERT_TRUE(A.estimate && A.wholeEstimate);
  EXPECT_EQ(A.wholeEstimate->hostBytes, kept->internal().estimate->hostBytes);
  EXPECT_NE(A.estimate->hostBytes, A.wholeEstimate->hostBytes);
  EXPECT_GT(A.estimate->hostBytes, meshHeldBytes(sphere) + estimateLatticeBytes(lattice) + A.estimate->deviceBytes);
  EXPECT_EQ(A.estimate->outputVertices, oneShot->subTriangles() * 10u);   // every patch vertex of level 3
}

// The accurate front (accurateStreamShape) from where each patch's boundary lies: the corners and points on
// the parents' edges held until their last parent, the rest while its parent is current. Each term counts:
// a sub-triangle's corner on a parent corner, on a parent edge, its edge along a parent edge.
TEST(StreamBudget, AccurateFrontCountsWhereThePatchBoundariesLie) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  m.weldId = {0, 1, 2, 3};
  m.triangles = {{0, 1, 2}, {1, 3, 2}};
  auto sub = [](uint32_t parent, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    SubTriangle s;
    s.parent = parent;
    s.corners[0].lam = a, s.corners[1].lam = b, s.corners[2].lam = c;
    return s;
  };
  const glm::dvec3 c0(1, 0, 0), c1(0, 1, 0), c2(0, 0, 1), mid01(0.5, 0.5, 0), mid12(0, 0.5, 0.5);
  // Parent 0 split at the middle of its edge 0-1 (not shared) into two; parent 1 whole.
  const std::vector<SubTriangle> subs = {sub(0, c0, mid01, c2), sub(0, mid01, c1, c2), sub(1, c0, c1, c2)};
  for (int level : {1, 3}) {
    const StreamShape s = accurateStreamShape(m, subs, level);
    const double nv = tessVertexCount(level);
    EXPECT_EQ(s.subTriangles, 3);
    // The front is largest at parent 0: its corners (3 locations); on its edge 0-1 the level - 1 points of
    // each half and the split point from each (2 level: counted twice, a bound), on its edges 1-2 and 2-0
    // level - 1 each; its two patches' 2 nv points.
    const double edgePoints = 2 * level + (level - 1) + (level - 1);
    EXPECT_EQ(s.frontLocations, 3 + edgePoints + 2 * nv) << level;
    // Vertices: corner 2 in both patches, corners 0 and 1 in one each.
    EXPECT_EQ(s.frontVertices, 4 + edgePoints + 2 * nv) << level;
  }
  EXPECT_THROW(accurateStreamShape(m, {subs[2], subs[0]}, 1), std::logic_error);
}

// A limit between the streamed and the whole job's estimate: the one-shot Deformer is made and streams its
// result, but result(), which holds the welded mesh, is refused before any work (smooth and accurate).
class OneShotOf : public ::testing::TestWithParam<Method> {};
INSTANTIATE_TEST_SUITE_P(Methods, OneShotOf, ::testing::Values(Method::Smooth, Method::Accurate),
                         [](const ::testing::TestParamInfo<Method>& m) { return m.param == Method::Smooth ? "smooth" : "accurate"; });

TEST_P(OneShotOf, ResultIsCheckedAgainstTheWholeJob) {
  Device device = cpuDevice();
  const Mesh torus = testMesh("torus.obj");
  const Lattice lattice = twisted(torus);
  DeformOptions o;
  o.method = GetParam();
  o.once = true;
  o.tess = GetParam() == Method::Smooth ? 6 : 12;
  Deformer probe(device, torus, lattice, o);
  const uint64_t streamed = probe.internal().estimate->hostBytes, whole = probe.internal().wholeEstimate->hostBytes;
  ASSERT_LT(streamed, whole);
  o.memoryLimit = (streamed + whole) / 2;
  Deformer d(device, torus, lattice, o);
  d.deform(lattice);
  NullSink sink;
  EXPECT_NO_THROW(d.streamResult(sink));
  Deformer e(device, torus, lattice, o);
  e.deform(lattice);
  try {
    (void)e.result();
    ADD_FAILURE() << "result() of a one-shot job was not checked against the whole job's estimate";
  } catch (const Error& err) {
    EXPECT_EQ(err.kind(), ErrorKind::Input);
    EXPECT_NE(std::string(err.what()).find(GetParam() == Method::Smooth ? "the smooth job needs about" : "the job needs about"),
              std::string::npos)
        << err.what();
  }
}

}  // namespace
