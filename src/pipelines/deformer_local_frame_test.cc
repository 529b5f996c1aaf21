// Models far from the origin (issue 12, item 2) and of any size: the Deformer computes in the lattice
// box's frame (deformer_local_frame.cpp), so a mesh and its lattice moved by 1e5..1e7 units give, on every
// device, the topology and (to float rounding of the model's size) the geometry of the untranslated run,
// and a model 2^k times as large gives 2^k times the result of size 1, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <sffd/sffd.h>

#include "api/api_test_support.h"
#include "core/job_budget.h"
#include "backends/backend_test_support.h"
#include "model/mesh_topology.h"
#include "pipelines/deformer_internal.h"

namespace {

using namespace sffd;

// A UV sphere of radius 1 (closed), or its part above z = -0.5 (open: one boundary loop).
Mesh uvSphere(bool open) {
  const int rings = 10, segments = 16;
  std::vector<double> xyz;
  std::vector<uint32_t> tri;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double th = M_PI * r / rings, ph = 2 * M_PI * s / segments;
      const double ring = r == 0 || r == rings ? 0.0 : std::sin(th);   // the poles exact, so welded
      xyz.insert(xyz.end(), {ring * std::cos(ph), ring * std::sin(ph), r == rings ? -1.0 : std::cos(th)});
    }
  const int lastRing = open ? 7 : rings;
  auto at = [&](int r, int s) { return uint32_t(r * segments + s % segments); };
  for (int r = 0; r < lastRing; ++r)
    for (int s = 0; s < segments; ++s) {
      if (r > 0) tri.insert(tri.end(), {at(r, s), at(r + 1, s), at(r, s + 1)});
      if (r + 1 < rings) tri.insert(tri.end(), {at(r, s + 1), at(r + 1, s), at(r + 1, s + 1)});
    }
  return sffd::testing::meshFromArrays(xyz, tri);
}

Mesh translatedMesh(const Mesh& mesh, glm::dvec3 by) { return worldMesh(mesh, LocalFrame{by, 1.0}); }
Mesh scaledMesh(const Mesh& mesh, double by) { return worldMesh(mesh, LocalFrame{glm::dvec3(0.0), 1 / by}); }

TEST(LocalFrame, OriginIsZeroNearTheWorldOriginAndTheBoxCentreFarFromIt) {
  const Mesh sphere = uvSphere(false);
  EXPECT_TRUE(latticeLocalFrame(fitLattice(sphere)).isWorld());
  const LocalFrame far = latticeLocalFrame(fitLattice(translatedMesh(sphere, glm::dvec3(1e6, -3e5, 0.25))));
  EXPECT_EQ(far.origin, glm::dvec3(1e6, -3e5, 0.0));   // the nearest multiples of 32 (the box is about 2 wide)
  EXPECT_EQ(far.scale, 1.0);
}

TEST(LocalFrame, ScaleIsOneForUsualSizesAndBringsOthersToSizeOne) {
  const Mesh sphere = uvSphere(false);   // its fitted box is a little over 2 across
  for (int k : {-9, -8, 0, 10}) EXPECT_EQ(latticeLocalFrame(fitLattice(scaledMesh(sphere, std::ldexp(1.0, k)))).scale, 1.0) << k;
  for (int k : {-100, -10, 11, 300}) {
    const LocalFrame frame = latticeLocalFrame(fitLattice(scaledMesh(sphere, std::ldexp(1.0, k))));
    EXPECT_EQ(frame.scale, std::ldexp(1.0, -k - 1)) << k;
    EXPECT_EQ(frame.origin, glm::dvec3(0.0)) << k;
  }
}

// A box below double's smallest normal number (2^-1022) has lost bits already, and the power of two that
// would bring it to size 1 is past double's range: an input Error for every method (classic wrote "a
// non-finite position", smooth "the edge length must be a finite number > 0", accurate an empty mesh).
TEST(LocalFrame, ABoxBelowDoublesNormalRangeIsRefused) {
  const Mesh sphere = scaledMesh(uvSphere(false), std::ldexp(1.0, -1032));
  const Lattice lattice = makeIdentityLattice(glm::dvec3(std::ldexp(-1.0, -1031)), glm::dvec3(std::ldexp(1.0, -1031)), {4, 4, 4}, {2, 2, 2});
  DeviceRequest cpu;
  cpu.name = "cpu";
  Device device = Device::open(cpu);
  for (Method method : {Method::Smooth, Method::Classic, Method::Accurate}) {
    DeformOptions o;
    o.method = method;
    try {
      Deformer deformer(device, sphere, lattice, o);
      ADD_FAILURE() << "method " << int(method) << " took a box of 2^-1030";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Input) << e.what();
      EXPECT_NE(std::string(e.what()).find("across, below the smallest normal double (2.2e-308)"), std::string::npos) << e.what();
    }
  }
}

TEST(LocalFrame, MeshesFarFromTheOriginKeepTheirTopologyAndGeometryOnEveryDevice) {
  std::vector<std::string> devices = sffd::testing::backendsHere(sffd::testing::testBackends());
  if (std::find(devices.begin(), devices.end(), "cpu") == devices.end()) devices.push_back("cpu");
  for (bool open : {false, true}) {
    const Mesh mesh = uvSphere(open);
    DeformOptions o;   // smooth, float, fast: the variant that lost the most far out
    o.tess = 3;
    o.edgeLength = 0.3;
    for (const std::string& name : devices) {
      DeviceRequest request;
      request.name = name;
      Device device = Device::open(request);
      Mesh reference;
      MeshTopology referenceTopology;
      for (double t : {0.0, 1e5, 1e6, 1e7}) {
        const glm::dvec3 by(t, -t, t);
        const Mesh moved = translatedMesh(mesh, by);
        Lattice lattice = fitLattice(moved, {4, 4, 4}, {2, 2, 2});
        applyLatticePreset(lattice, "twist", 0.3);
        Deformer deformer(device, moved, lattice, o);
        deformer.deform(lattice);
        const Mesh out = translatedMesh(deformer.result(), -by);
        const MeshTopology topology = buildTopology(out);
        const std::string what = name + (open ? " open" : " closed") + " at " + std::to_string(t);
        if (t == 0) {
          reference = out, referenceTopology = topology;
          EXPECT_EQ(topology.nonManifoldEdges, 0u) << what;
          EXPECT_EQ(topology.boundaryEdges == 0, !open) << what;
          continue;
        }
        ASSERT_EQ(out.triangles.size(), reference.triangles.size()) << what;
        EXPECT_EQ(topology.boundaryEdges, referenceTopology.boundaryEdges) << what;
        EXPECT_EQ(topology.nonManifoldEdges, 0u) << what;
        // Same vertices in the same order, within float rounding of the model's size (2): the
        // untranslated run's error relative to the model is what the far ones have.
        ASSERT_EQ(out.positions.size(), reference.positions.size()) << what;
        double worst = 0;
        for (size_t v = 0; v < out.positions.size(); ++v)
          worst = std::max(worst, glm::length(out.positions[v] - reference.positions[v]));
        EXPECT_LT(worst, 2e-5) << what;
        // Consistently oriented: the enclosed volume keeps its sign (and size).
        auto volume = [](const Mesh& m) {
          double v = 0;
          for (const auto& tr : m.triangles) v += glm::dot(m.positions[tr[0]], glm::cross(m.positions[tr[1]], m.positions[tr[2]]));
          return v / 6;
        };
        EXPECT_NEAR(volume(out), volume(reference), 1e-4 * std::abs(volume(reference))) << what;
      }
    }
  }
}

// The host's estimates and lattice presets at sizes whose squared lengths leave double's range: the
// sub-triangle estimate said "about inf" (a mesh 1e100 across) or 0 (1e-200), and a preset called a box
// 1e-300 across degenerate.
TEST(LocalFrame, EstimatesAndPresetsHoldAtEverySize) {
  const Mesh mesh = uvSphere(false);
  const double reference = estimateSubTriangles(mesh, 0.3);
  Lattice unit = fitLattice(mesh, {4, 4, 4}, {2, 2, 2});
  applyLatticePreset(unit, "bend", 0.3);
  for (int k : {-1000, -500, -100, 100, 500, 1000}) {
    const double size = std::ldexp(1.0, k);
    const Mesh scaled = scaledMesh(mesh, size);
    EXPECT_NEAR(estimateSubTriangles(scaled, 0.3 * size), reference, 1e-9 * reference) << k;
    Lattice lattice = fitLattice(scaled, {4, 4, 4}, {2, 2, 2});
    ASSERT_NO_THROW(applyLatticePreset(lattice, "bend", 0.3)) << k;
    for (size_t i = 0; i < unit.controlPoints.size(); ++i)
      EXPECT_LT(glm::length(lattice.controlPoints[i] / size - unit.controlPoints[i]), 1e-12) << k << " point " << i;
  }
}

// Below about 1e-6 and above 1e6 units the kernels' thresholds (a squared length below float's smallest
// normal number has no direction; products of six lengths past float's range) once changed the result by 2 %
// of its size, and from 1e-20 or 1e20 broke it (a non-finite normal). Now every size computes as size 1:
// scales by powers of two are exact, so the results are the size-1 run's times 2^k, bit for bit.
TEST(LocalFrame, EveryModelSizeGivesTheResultOfSizeOneScaled) {
  std::vector<std::string> devices = sffd::testing::backendsHere(sffd::testing::testBackends());
  if (std::find(devices.begin(), devices.end(), "cpu") == devices.end()) devices.push_back("cpu");
  const Mesh mesh = uvSphere(false);
  for (const std::string& name : devices) {
    DeviceRequest request;
    request.name = name;
    Device device = Device::open(request);
    for (Method method : {Method::Smooth, Method::Classic, Method::Accurate}) {
      DeformOptions o;
      o.method = method;
      o.tess = 3;
      o.precision = Precision::Float;
      Mesh reference;
      for (int k : {0, -100, -30, -10, 12, 40, 100}) {
        const double size = std::ldexp(1.0, k);
        const Mesh scaled = scaledMesh(mesh, size);
        Lattice lattice = fitLattice(scaled, {4, 4, 4}, {2, 2, 2});
        applyLatticePreset(lattice, "twist", 0.3);
        o.edgeLength = 0.3 * size;
        Deformer deformer(device, scaled, lattice, o);
        deformer.deform(lattice);
        const Mesh out = scaledMesh(deformer.result(), 1 / size);
        const std::string what = name + " method " + std::to_string(int(method)) + " at 2^" + std::to_string(k);
        if (k == 0) {
          reference = out;
          continue;
        }
        EXPECT_NE(deformer.localScale(), 1.0) << what;
        ASSERT_EQ(out.triangles, reference.triangles) << what;
        ASSERT_EQ(out.positions.size(), reference.positions.size()) << what;
        size_t differ = 0;
        for (size_t v = 0; v < out.positions.size(); ++v)
          differ += out.positions[v] != reference.positions[v] || out.normals[v] != reference.normals[v];
        EXPECT_EQ(differ, 0u) << what;
      }
    }
  }
}

}  // namespace
