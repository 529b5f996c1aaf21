// The host-memory estimate of a streamed smooth job (stream_budget.h): its sub-triangle bound holds for
// every clipping, only a streamed job gets it, and a one-shot result() is still checked against the
// whole job's. That it bounds the peak RSS: MemoryLimit.StreamedEstimateBoundsThePeak (tests/).
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

  DeformOptions accurate;
  accurate.once = true;
  accurate.method = Method::Accurate;
  EXPECT_FALSE(made(accurate)->internal().estimate);   // its own estimate, in its run (deformer_accurate.cpp)
}

// A limit between the streamed and the whole job's estimate: the one-shot Deformer is made and streams its
// result, but result(), which holds the welded mesh, is refused before any work.
TEST(StreamBudget, OneShotResultIsCheckedAgainstTheWholeJob) {
  Device device = cpuDevice();
  const Mesh torus = testMesh("torus.obj");
  const Lattice lattice = twisted(torus);
  DeformOptions o;
  o.once = true;
  o.tess = 6;
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
    EXPECT_NE(std::string(err.what()).find("the smooth job needs about"), std::string::npos) << err.what();
  }
}

}  // namespace
