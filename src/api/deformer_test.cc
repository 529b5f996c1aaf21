// sffd::Deformer through the public headers only, on every device there is (the required GPU
// backends, and the CPU reference): every method, strict results equal across devices, re-deforming,
// refusals, views of the caller's arrays, cancelling, chunking. Meshes are made here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <thread>

#include <sffd/sffd.h>

#include "api/api_test_support.h"
#include "backends/backend_test_support.h"

namespace {

using namespace sffd;

// An icosphere of radius 1: the icosahedron with every triangle split in four `levels` times.
Mesh icosphere(int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<double> xyz = {-1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0, 0, -1, t, 0, 1, t,
                             0, -1, -t, 0, 1, -t, t, 0, -1, t, 0, 1, -t, 0, -1, -t, 0, 1};
  std::vector<uint32_t> tri = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
                               3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto middle = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      for (int c = 0; c < 3; ++c) xyz.push_back((xyz[3 * a + c] + xyz[3 * b + c]) / 2);
      return mid[key] = uint32_t(xyz.size() / 3 - 1);
    };
    std::vector<uint32_t> next;
    for (size_t i = 0; i < tri.size(); i += 3) {
      uint32_t a = tri[i], b = tri[i + 1], c = tri[i + 2], ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    tri = next;
  }
  for (size_t v = 0; v < xyz.size(); v += 3) {
    double n = std::sqrt(xyz[v] * xyz[v] + xyz[v + 1] * xyz[v + 1] + xyz[v + 2] * xyz[v + 2]);
    for (int c = 0; c < 3; ++c) xyz[v + c] /= n;
  }
  return sffd::testing::meshFromArrays(xyz, tri);
}

// The devices there are: the GPU backends this machine has and the CPU reference.
std::vector<std::string> deviceNames() {
  std::vector<std::string> names = sffd::testing::backendsHere(sffd::testing::testBackends());
  names.push_back("cpu");
  return names;
}

Device openDevice(const std::string& name) { return sffd::testing::openTestDevice(name); }

Lattice twisted(const Mesh& mesh, double amount) {
  Lattice L = fitLattice(mesh, {4, 5, 5}, {2, 2, 3});
  applyLatticePreset(L, "twist", amount);
  return L;
}

DeformOptions strictOptions(Method method) {
  DeformOptions o;
  o.method = method;
  o.strict = true;
  o.precision = Precision::Float;   // every device has it
  o.tess = 3;
  o.edgeLength = 0.4;
  return o;
}

// Bit-for-bit equality of two meshes' vertices, normals and triangles.
void expectSameBits(const Mesh& a, const Mesh& b, const std::string& what) {
  ASSERT_EQ(a.positions.size(), b.positions.size()) << what;
  ASSERT_EQ(a.triangles.size(), b.triangles.size()) << what;
  EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(glm::dvec3)), 0) << what;
  EXPECT_EQ(std::memcmp(a.normals.data(), b.normals.data(), a.normals.size() * sizeof(glm::dvec3)), 0) << what;
  EXPECT_EQ(a.triangles, b.triangles) << what;
}

const Method kMethods[] = {Method::Smooth, Method::Accurate, Method::Classic};
const char* nameOf(Method m) { return m == Method::Smooth ? "smooth" : m == Method::Accurate ? "accurate" : "classic"; }

TEST(Deformer, EveryMethodOnEveryDeviceGivesTheCpuReferenceBits) {
  const Mesh mesh = icosphere(2);
  const Lattice lattice = twisted(mesh, 0.6);
  for (Method method : kMethods) {
    Device cpu = openDevice("cpu");
    Deformer reference(cpu, mesh, lattice, strictOptions(method));
    reference.deform(lattice);
    const Mesh expected = reference.result();
    EXPECT_GT(expected.triangles.size(), 0u);
    if (method != Method::Classic) { EXPECT_GT(reference.subTriangles(), mesh.triangles.size() - 1); }
    for (const std::string& name : deviceNames()) {
      if (name == "cpu") continue;
      Device device = openDevice(name);
      Deformer deformer(device, mesh, lattice, strictOptions(method));
      deformer.deform(lattice);
      expectSameBits(deformer.result(), expected, name + " " + nameOf(method));
      EXPECT_EQ(deformer.subTriangles(), reference.subTriangles());
      std::vector<OutputChunk> chunks = deformer.deviceOutput();
      ASSERT_FALSE(chunks.empty()) << name;
      EXPECT_GT(chunks[0].bytes, 0u);
    }
  }
}

TEST(Deformer, RedeformingEqualsAFreshDeformerAndOtherStructuresAreRefused) {
  const Mesh mesh = icosphere(2);
  const Lattice a = twisted(mesh, 0.3), b = twisted(mesh, -0.5);
  for (const std::string& name : deviceNames())
    for (Method method : kMethods) {
      SCOPED_TRACE(name + " " + nameOf(method));
      Device device = openDevice(name);
      Deformer reused(device, mesh, a, strictOptions(method));
      reused.deform(a);
      reused.deform(b);
      Deformer fresh(device, mesh, b, strictOptions(method));
      fresh.deform(b);
      expectSameBits(reused.result(), fresh.result(), "re-deformed");
      Lattice other = fitLattice(mesh, {5, 5, 5}, {2, 2, 2});
      try {
        reused.deform(other);
        ADD_FAILURE() << "a lattice of another structure was accepted";
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Input);
      }
    }
}

TEST(Deformer, MeshViewsOfFloatsDoublesAndStridesEqualTheFile) {
  // A cube (coordinates exact in float), as an OBJ file and as the caller's arrays.
  const std::vector<double> corners = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  const std::vector<uint32_t> tri = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                     1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  const std::string path = (std::filesystem::temp_directory_path() / "sffd_api_cube.obj").string();
  {
    std::ofstream obj(path);
    for (size_t v = 0; v < 8; ++v) obj << "v " << corners[3 * v] << " " << corners[3 * v + 1] << " " << corners[3 * v + 2] << "\n";
    for (size_t t = 0; t < tri.size(); t += 3) obj << "f " << tri[t] + 1 << " " << tri[t + 1] + 1 << " " << tri[t + 2] + 1 << "\n";
  }
  const Mesh fromFile = readMesh(path);
  std::filesystem::remove(path);
  std::vector<double> strided(8 * 5, -7.0);   // 5 doubles a vertex, 2 of them padding
  std::vector<float> floats(corners.begin(), corners.end());
  for (size_t v = 0; v < 8; ++v)
    for (int c = 0; c < 3; ++c) strided[5 * v + c] = corners[3 * v + c];
  MeshView doubles, singles;
  doubles.positions = strided.data();
  doubles.positionStride = 5;
  singles.positionsF32 = floats.data();
  for (MeshView* v : {&doubles, &singles}) v->vertexCount = 8, v->triangles = tri.data(), v->triangleCount = 12;

  Lattice lattice = twisted(fromFile, 0.4);
  Device device = openDevice(deviceNames().front());
  for (Method method : kMethods) {
    Deformer file(device, fromFile, lattice, strictOptions(method));
    file.deform(lattice);
    const Mesh expected = file.result();
    for (const MeshView* view : {&doubles, &singles}) {
      Deformer fromView(device, *view, lattice, strictOptions(method));
      fromView.deform(lattice);
      expectSameBits(fromView.result(), expected, std::string(nameOf(method)) + (view == &doubles ? " doubles" : " floats"));
    }
  }
}

TEST(Deformer, CancellingThrowsCancelledAndLeavesItUsable) {
  const Mesh mesh = icosphere(2);
  const Lattice lattice = twisted(mesh, 0.5);
  for (const std::string& name : deviceNames())
    for (Method method : kMethods) {
      SCOPED_TRACE(name + " " + nameOf(method));
      Device device = openDevice(name);
      bool cancel = true;
      std::vector<std::string> stages;
      DeformOptions o = strictOptions(method);
      o.progress = [&](const Progress& p) {
        stages.push_back(p.stage);
        EXPECT_GE(p.fraction, 0.0);
        EXPECT_LE(p.fraction, 1.0);
        return !(cancel && std::string(p.stage) == "deform" && p.fraction > 0);   // after some of the work
      };
      Deformer deformer(device, mesh, lattice, o);
      EXPECT_FALSE(stages.empty());
      try {
        deformer.deform(lattice);
        ADD_FAILURE() << "not cancelled";
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Cancelled);
        EXPECT_EQ(e.exitStatus(), 1);
      }
      cancel = false;
      deformer.deform(lattice);
      Deformer fresh(device, mesh, lattice, strictOptions(method));
      fresh.deform(lattice);
      expectSameBits(deformer.result(), fresh.result(), "after a cancelled deform");
      // Cancelled while it prepares: no Deformer, nothing left behind on the device.
      o.progress = [](const Progress&) { return false; };
      try {
        Deformer never(device, mesh, lattice, o);
        ADD_FAILURE() << "not cancelled";
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Cancelled);
      }
    }
}

TEST(Deformer, SmallChunksGiveTheSameBits) {
  const Mesh mesh = icosphere(2);
  const Lattice lattice = twisted(mesh, 0.5);
  for (const std::string& name : deviceNames())
    for (Method method : kMethods) {
      SCOPED_TRACE(name + " " + nameOf(method));
      Device device = openDevice(name);
      Deformer whole(device, mesh, lattice, strictOptions(method));
      whole.deform(lattice);
      DeformOptions o = strictOptions(method);
      o.maxChunkElements = 37;   // many chunks, the last one partial
      Deformer chunked(device, mesh, lattice, o);
      chunked.deform(lattice);
      expectSameBits(chunked.result(), whole.result(), "chunked");
      if (name != "cpu") { EXPECT_GT(chunked.deviceOutput().size(), 2u); }
    }
}

TEST(Deformer, OptionsAreCheckedAndDefaulted) {
  const Mesh mesh = icosphere(1);
  const Lattice lattice = twisted(mesh, 0.2);
  Device device = openDevice("cpu");
  for (int tess : {0, 65}) {
    DeformOptions o;
    o.tess = tess;
    EXPECT_THROW(Deformer(device, mesh, lattice, o), Error) << tess;
  }
  DeformOptions o;
  o.edgeLength = -1;
  EXPECT_THROW(Deformer(device, mesh, lattice, o), Error);
  // Auto precision: double for classic and accurate where the device has it, float for smooth.
  DeformOptions classic;
  classic.method = Method::Classic;
  EXPECT_TRUE(Deformer(device, mesh, lattice, classic).doublePrecision());
  EXPECT_FALSE(Deformer(device, mesh, lattice, {}).doublePrecision());
  // A memory limit too small for the job is an input error naming it.
  classic.memoryLimit = 1024;
  try {
    Deformer(device, mesh, lattice, classic);
    ADD_FAILURE() << "the memory limit was not applied";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
    EXPECT_NE(std::string(e.what()).find("memoryLimit"), std::string::npos) << e.what();
  }
  // Smooth too, before anything is allocated (issue 12: smooth jobs ignored the limit).
  DeformOptions smooth;
  smooth.memoryLimit = 64 << 10;
  try {
    Deformer(device, mesh, lattice, smooth);
    ADD_FAILURE() << "the memory limit was not applied to smooth";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
    EXPECT_NE(std::string(e.what()).find("(DeformOptions::memoryLimit)"), std::string::npos) << e.what();
    // In the library's words, not the tool's flags (which the tool puts in: MemoryLimit.*).
    EXPECT_NE(std::string(e.what()).find("a longer edge length or a lower tessellation level"), std::string::npos) << e.what();
  }
}

// The kind of the Error `f` throws, or none.
template <class F>
std::optional<ErrorKind> errorKindOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.kind();
  }
  return std::nullopt;
}

// A stranger's adoption test (2026-11-29): result() before the first deform() handed over whatever the
// device's fresh buffers held (welded into a different mesh on each device), and after a cancelled
// deform() a mix of two lattices' outputs.
TEST(Deformer, ResultsBeforeADeformOrAfterACancelledOneAreRefused) {
  const Mesh mesh = icosphere(1);
  const Lattice a = twisted(mesh, 0.3), b = twisted(mesh, -0.4);
  struct Count : MeshSink {
    size_t vertices = 0;
    void add(const Mesh& piece, size_t) override { vertices += piece.positions.size(); }
  };
  for (const std::string& name : deviceNames())
    for (Method method : kMethods) {
      SCOPED_TRACE(name + " " + nameOf(method));
      Device device = openDevice(name);
      bool cancel = false;
      DeformOptions o = strictOptions(method);
      o.progress = [&](const Progress& p) { return !(cancel && std::string(p.stage) == "deform" && p.fraction > 0); };
      Deformer deformer(device, mesh, a, o);
      Count sink;
      EXPECT_EQ(errorKindOf([&] { deformer.result(); }), ErrorKind::Input);
      EXPECT_EQ(errorKindOf([&] { deformer.streamResult(sink); }), ErrorKind::Input);
      EXPECT_EQ(errorKindOf([&] { deformer.patchControlPoints(); }), ErrorKind::Input);
      EXPECT_TRUE(deformer.deviceOutput().empty());
      EXPECT_EQ(sink.vertices, 0u);
      deformer.deform(a);
      const Mesh first = deformer.result();
      cancel = true;
      EXPECT_EQ(errorKindOf([&] { deformer.deform(b); }), ErrorKind::Cancelled);
      cancel = false;
      EXPECT_EQ(errorKindOf([&] { deformer.result(); }), ErrorKind::Input);
      EXPECT_EQ(errorKindOf([&] { deformer.streamResult(sink); }), ErrorKind::Input);
      EXPECT_TRUE(deformer.deviceOutput().empty());
      deformer.deform(a);
      expectSameBits(deformer.result(), first, "deformed again after the cancelled call");
      if (name != "cpu") { EXPECT_FALSE(deformer.deviceOutput().empty()); }
    }
}

// DeformOptions::once promised a second deform() or result() throws; Classic took both.
TEST(Deformer, OneShotDeformsOnceAndGivesItsResultOnceForEveryMethod) {
  const Mesh mesh = icosphere(1);
  const Lattice lattice = twisted(mesh, 0.3);
  Device device = openDevice("cpu");
  for (Method method : kMethods) {
    SCOPED_TRACE(nameOf(method));
    DeformOptions o = strictOptions(method);
    o.once = true;
    Deformer deformer(device, mesh, lattice, o);
    deformer.deform(lattice);
    EXPECT_EQ(errorKindOf([&] { deformer.deform(lattice); }), ErrorKind::Input);
    EXPECT_GT(deformer.result().triangles.size(), 0u);
    EXPECT_EQ(errorKindOf([&] { deformer.result(); }), ErrorKind::Input);
  }
}

// An out-of-range samples or creaseAngleDeg was taken silently (a negative samples as the default, a NaN
// or 1000 degrees as some rule), unlike the tool's and Python's; an empty mesh made smooth FFD ask for a
// positive edge length the caller never gave, where accurate and classic give an empty result.
TEST(Deformer, OutOfRangeOptionsAreRefusedAndAnEmptyMeshDeforms) {
  const Mesh mesh = icosphere(1);
  const Lattice lattice = twisted(mesh, 0.2);
  Device device = openDevice("cpu");
  for (Method method : kMethods) {
    SCOPED_TRACE(nameOf(method));
    for (int samples : {-1, 16}) {
      DeformOptions o = strictOptions(method);
      o.samples = samples;
      EXPECT_EQ(errorKindOf([&] { Deformer(device, mesh, lattice, o); }), ErrorKind::Input) << samples;
    }
    for (double angle : {-0.5, 180.5, 1e9, std::nan("")}) {
      DeformOptions o = strictOptions(method);
      o.creaseAngleDeg = angle;
      EXPECT_EQ(errorKindOf([&] { Deformer(device, mesh, lattice, o); }), ErrorKind::Input) << angle;
    }
    for (double angle : {0.0, 180.0, kCreaseAngleAuto}) {
      DeformOptions o = strictOptions(method);
      o.creaseAngleDeg = angle;
      EXPECT_EQ(errorKindOf([&] { Deformer(device, mesh, lattice, o); }), std::nullopt) << angle;
    }
    DeformOptions o = strictOptions(method);
    o.edgeLength = 0;   // the default, a tenth of a size the empty mesh does not have
    Deformer empty(device, Mesh{}, lattice, o);
    empty.deform(lattice);
    EXPECT_TRUE(empty.result().positions.empty());
  }
}

// A Deformer held the address of its Device: a Device moved (a std::vector of them growing) left it
// pointing at the moved-from object, and any call crashed; so did every call on a moved-from Device or
// Deformer.
TEST(Deformer, FollowsItsDeviceWhenMovedAndMovedFromObjectsThrow) {
  const Mesh mesh = icosphere(1);
  const Lattice lattice = twisted(mesh, 0.3);
  for (const std::string& name : deviceNames()) {
    SCOPED_TRACE(name);
    std::optional<Device> away;   // declared before the Deformers, which must not outlive their Device
    std::vector<Device> devices;
    devices.push_back(openDevice(name));
    Deformer deformer(devices[0], mesh, lattice, strictOptions(Method::Smooth));
    for (int i = 0; i < 8; ++i) devices.push_back(openDevice("cpu"));   // moves devices[0] at least once
    EXPECT_EQ(&deformer.device(), &devices[0]);
    deformer.deform(lattice);
    const Mesh moved = deformer.result();
    Deformer fresh(devices[0], mesh, lattice, strictOptions(Method::Smooth));
    fresh.deform(lattice);
    expectSameBits(moved, fresh.result(), "after its Device was moved");
    away.emplace(std::move(devices[0]));
    EXPECT_EQ(&deformer.device(), &*away);
    EXPECT_EQ(errorKindOf([&] { (void)devices[0].label(); }), ErrorKind::Input);
    EXPECT_EQ(errorKindOf([&] { (void)devices[0].info(); }), ErrorKind::Input);
    EXPECT_EQ(errorKindOf([&] { Deformer(devices[0], mesh, lattice); }), ErrorKind::Input);
    Deformer taken = std::move(deformer);
    EXPECT_EQ(errorKindOf([&] { deformer.deform(lattice); }), ErrorKind::Input);
    EXPECT_EQ(errorKindOf([&] { deformer.result(); }), ErrorKind::Input);
    EXPECT_EQ(errorKindOf([&] { (void)deformer.subTriangles(); }), ErrorKind::Input);
    deformer = Deformer(*away, mesh, lattice, strictOptions(Method::Smooth));   // assigned again: usable
    deformer.deform(lattice);
    expectSameBits(deformer.result(), moved, "a moved-from Deformer assigned again");
    taken.deform(lattice);
  }
}

// A GL device used from one thread, then another, and destroyed on a third, as <sffd/sffd.h> allows of
// every device: EGL keeps a context current on one thread only (EGL_BAD_ACCESS elsewhere), so sffd lets it
// go at the end of every call. Before, a second thread's deform() was refused and a Deformer or Device
// destroyed there threw from its destructor (std::terminate); Python's garbage collector does that.
TEST(Deformer, AGlDeviceIsUsedAndDestroyedOnAnyThread) {
  const std::vector<std::string> names = sffd::testing::backendsHere({"gl-egl", "gles", "gl-osmesa"});
  if (names.empty()) GTEST_SKIP() << "no GL device here";
  const Mesh mesh = icosphere(1);
  const Lattice lattice = twisted(mesh, 0.3);
  // Runs `f` on a thread of its own; what it throws is a failure, not std::terminate.
  auto onAnotherThread = [](const std::function<void()>& f) {
    std::thread([&] {
      try {
        f();
      } catch (const std::exception& e) {
        ADD_FAILURE() << e.what();
      }
    }).join();
  };
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    std::optional<Device> device(openDevice(name));
    std::optional<Deformer> deformer(std::in_place, *device, mesh, lattice, strictOptions(Method::Smooth));
    deformer->deform(lattice);
    const Mesh first = deformer->result();
    onAnotherThread([&] {
      deformer->deform(lattice);
      expectSameBits(deformer->result(), first, name + ", second thread");
    });
    deformer->deform(lattice);   // back on the first thread
    expectSameBits(deformer->result(), first, name + ", first thread again");
    onAnotherThread([&] {
      deformer.reset();
      device.reset();
    });
    // Opened and used on a thread that then ends, destroyed here (Python: a worker's Deformer collected
    // on the main thread).
    onAnotherThread([&] {
      device.emplace(openDevice(name));
      deformer.emplace(*device, mesh, lattice, strictOptions(Method::Classic));
      deformer->deform(lattice);
    });
    EXPECT_FALSE(deformer->result().positions.empty());
    deformer.reset();
    device.reset();
  }
}

// The constructor refused a lattice with a non-finite control point, deform() took one (an edited lattice,
// Python's control_points = P) and gave a result of NaN.
TEST(Deformer, DeformRefusesANonFiniteControlPoint) {
  const Mesh mesh = icosphere(1);
  const Lattice lattice = twisted(mesh, 0.3);
  Device device = openDevice("cpu");
  for (Method method : kMethods) {
    SCOPED_TRACE(nameOf(method));
    Deformer deformer(device, mesh, lattice, strictOptions(method));
    for (double bad : {std::nan(""), HUGE_VAL}) {
      Lattice edited = lattice;
      edited.controlPoints[17].y = bad;
      EXPECT_EQ(errorKindOf([&] { deformer.deform(edited); }), ErrorKind::Input) << bad;
    }
    deformer.deform(lattice);
    EXPECT_TRUE(std::isfinite(deformer.result().positions[0].x));
  }
}

}  // namespace

namespace {

// The message of the input Error `f` throws ("" and a failure when it throws none).
template <class F>
std::string inputMessageOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "nothing was thrown";
  return "";
}

// An audit (2026-12): a Mesh handed to the Deformer was not checked as a MeshView is (meshFromView): an
// index out of range or a field shorter than the positions was read out of bounds (a crash, a corrupt
// heap), a NaN normal deformed into NaN, a NaN position gave misleading errors or dropped triangles, and
// an empty weldId crashed. Each is now an input error naming the field and its first bad element; an
// empty weldId or normals is made as readMesh makes it.
TEST(Deformer, AMeshIsCheckedAsAViewIsAndItsOptionalFieldsAreMade) {
  const Mesh mesh = icosphere(1);
  const Lattice lattice = twisted(mesh, 0.3);
  Device device = openDevice("cpu");
  const std::pair<const char*, void (*)(Mesh&)> bad[] = {
      {"triangles[3]: vertex index 999999 out of range", [](Mesh& m) { m.triangles[3][1] = 999999; }},
      {"positions[5] is non-finite", [](Mesh& m) { m.positions[5].x = std::nan(""); }},
      {"positions[6] is non-finite", [](Mesh& m) { m.positions[6].y = HUGE_VAL; }},
      {"normals[7] is non-finite", [](Mesh& m) { m.normals[7].z = std::nan(""); }},
      {"normals has 3 entries for 42 vertices", [](Mesh& m) { m.normals.resize(3); }},
      {"weldId has 41 entries", [](Mesh& m) { m.weldId.pop_back(); }},
      {"weldId[2] is 42, not below 42 vertices", [](Mesh& m) { m.weldId[2] = 42; }},
      {"texcoords has 2 entries", [](Mesh& m) { m.texcoords.resize(2); }},
      {"colors has 50 entries", [](Mesh& m) { m.colors.resize(50); }},
      {"triangleMaterial[0] is 0, not below 0 materials", [](Mesh& m) { m.triangleMaterial.assign(m.triangles.size(), 0); }},
      {"triangleGroup has 1 entries for 80 triangles", [](Mesh& m) { m.triangleGroup = {Mesh::kNoIndex}; }},
  };
  for (Method method : kMethods)
    for (const auto& [what, spoil] : bad) {
      SCOPED_TRACE(std::string(nameOf(method)) + ": " + what);
      Mesh m = mesh;
      spoil(m);
      const std::string message = inputMessageOf([&] { Deformer(device, m, lattice, strictOptions(method)); });
      EXPECT_EQ(message.rfind(std::string("mesh: ") + what, 0), 0u) << message;
    }
  for (Method method : kMethods) {
    SCOPED_TRACE(nameOf(method));
    Deformer whole(device, mesh, lattice, strictOptions(method));
    whole.deform(lattice);
    Mesh bare = mesh;
    bare.weldId.clear();
    Deformer unwelded(device, bare, lattice, strictOptions(method));
    unwelded.deform(lattice);
    expectSameBits(unwelded.result(), whole.result(), "without weldId");
    bare.normals.clear();   // the icosphere's normals were computed too (meshFromView)
    Deformer withoutNormals(device, bare, lattice, strictOptions(method));
    withoutNormals.deform(lattice);
    expectSameBits(withoutNormals.result(), whole.result(), "without normals");
  }
}

// A caller's weldId that put one id at two positions deformed silently: the crease cube with a split
// corner moved 1e-3 came out of accurate FFD with 18 open edges, with two corners under one id out of
// smooth FFD with 1,962 triangles fewer and 120 open edges, with every id 0 empty. Now an input error
// naming the first vertex away from its id's first vertex; other labels of the same locations deform to
// the same bits, and a split corner given an id of its own (two sheets touching there) deforms.
TEST(Deformer, AWeldIdAtTwoPositionsIsRefusedAndAnyLabelsAreTaken) {
  const Mesh cube = readMesh(SFFD_TEST_DATA "/cube2.obj");   // 24 vertices at 8 positions, ids 0..7
  const Lattice lattice = twisted(cube, 0.3);
  Mesh moved = cube, joined = cube, smallest = cube, apart = cube;
  moved.positions[0].x += 1e-3;
  joined.weldId[2] = joined.weldId[0];
  for (size_t v = 0; v < cube.positions.size(); ++v)
    smallest.weldId[v] = uint32_t(std::find(cube.positions.begin(), cube.positions.end(), cube.positions[v]) - cube.positions.begin());
  apart.weldId[0] = uint32_t(cube.positions.size() - 1);
  for (const std::string& name : deviceNames()) {
    Device device = openDevice(name);
    for (Method method : kMethods) {
      SCOPED_TRACE(name + " " + nameOf(method));
      EXPECT_EQ(inputMessageOf([&] { Deformer(device, moved, lattice, strictOptions(method)); }),
                "mesh: weldId[8] is 0, as vertex 0's, but vertex 8 is at (1, -1, 1) and vertex 0 at (1.001, -1, 1): vertices with one "
                "weld id must be at one position (leave weldId empty to weld by position)");
      EXPECT_EQ(inputMessageOf([&] { Deformer(device, joined, lattice, strictOptions(method)); })
                    .rfind("mesh: weldId[2] is 0, as vertex 0's, but vertex 2 is at (-1, -1, -1)", 0),
                0u);
      Deformer reference(device, cube, lattice, strictOptions(method)), relabelled(device, smallest, lattice, strictOptions(method)),
          twoSheets(device, apart, lattice, strictOptions(method));
      for (Deformer* d : {&reference, &relabelled, &twoSheets}) d->deform(lattice);
      expectSameBits(relabelled.result(), reference.result(), "ids as the smallest vertex index");
      EXPECT_EQ(twoSheets.result().triangles.size(), reference.result().triangles.size());
    }
  }
}

// deformer.h promised result() throws after a deform() that threw; after one refused for its lattice (a
// NaN control point, another structure) result() gave the previous lattice's result.
TEST(Deformer, ADeformRefusedForItsLatticeLeavesNoResult) {
  const Mesh mesh = icosphere(1);
  const Lattice lattice = twisted(mesh, 0.3);
  Device device = openDevice("cpu");
  Lattice nan = lattice, other = fitLattice(mesh, {5, 5, 5}, {2, 2, 2});
  nan.controlPoints[3].x = std::nan("");
  struct Count : MeshSink {
    void add(const Mesh&, size_t) override {}
  } sink;
  for (Method method : kMethods)
    for (const Lattice* refused : {&nan, &other}) {
      SCOPED_TRACE(nameOf(method));
      Deformer deformer(device, mesh, lattice, strictOptions(method));
      deformer.deform(lattice);
      const Mesh first = deformer.result();
      EXPECT_EQ(errorKindOf([&] { deformer.deform(*refused); }), ErrorKind::Input);
      EXPECT_NE(inputMessageOf([&] { deformer.result(); }).find("the last deform() was cancelled or failed"), std::string::npos);
      EXPECT_EQ(errorKindOf([&] { deformer.streamResult(sink); }), ErrorKind::Input);
      EXPECT_TRUE(deformer.deviceOutput().empty());
      if (method == Method::Smooth) { EXPECT_EQ(errorKindOf([&] { deformer.patchControlPoints(); }), ErrorKind::Input); }
      deformer.deform(lattice);
      expectSameBits(deformer.result(), first, "deformed again after the refused call");
    }
}

// A one-shot result cancelled while it was made was refused on a retry as "already taken".
TEST(Deformer, ARetriedOneShotResultSaysItWasCancelled) {
  const Mesh mesh = icosphere(1);
  const Lattice lattice = twisted(mesh, 0.3);
  Device device = openDevice("cpu");
  for (Method method : kMethods) {
    SCOPED_TRACE(nameOf(method));
    bool cancel = false;
    DeformOptions o = strictOptions(method);
    o.once = true;
    o.progress = [&](const Progress& p) { return !(cancel && p.fraction > 0); };
    Deformer deformer(device, mesh, lattice, o);
    deformer.deform(lattice);
    cancel = true;
    EXPECT_EQ(errorKindOf([&] { deformer.result(); }), ErrorKind::Cancelled);
    cancel = false;
    const std::string message = inputMessageOf([&] { deformer.result(); });
    EXPECT_NE(message.find("was cancelled while it was being made"), std::string::npos) << message;
    EXPECT_EQ(message.find("already taken"), std::string::npos) << message;
  }
}

// tessVertexCount(100000) gave 705182705, 1000000 a negative count, -1 gave 0.
TEST(Deformer, TessellationCountsTakeTheLevelsDeformOptionsTakes) {
  EXPECT_EQ(tessVertexCount(1), 3);
  EXPECT_EQ(tessTriangleCount(1), 1);
  EXPECT_EQ(tessVertexCount(64), 65 * 66 / 2);
  EXPECT_EQ(tessTriangleCount(64), 4096);
  for (int level : {-1, 0, 65, 100000, 1000000}) {
    EXPECT_NE(inputMessageOf([&] { tessVertexCount(level); }).find("1..64, not " + std::to_string(level)), std::string::npos);
    EXPECT_EQ(errorKindOf([&] { tessTriangleCount(level); }), ErrorKind::Input) << level;
  }
}

// A triangle with two corners at one position (a duplicate vertex, as unwelded STL files have them) has no
// area: smooth and accurate FFD leave its patches out. Its patch, fitted to the duplicate's own normal, stuck
// out of the cube's face by 0.03 and made the cube's edge non-manifold; the cube stays the cube now.
TEST(Deformer, ATriangleWithoutAreaLeavesNoPatch) {
  const std::vector<double> corners = {-1, -1, -1, 1, -1, -1, -1, 1, -1, 1, 1, -1, -1, -1, 1, 1, -1, 1, -1, 1, 1, 1, 1, 1};
  const std::vector<uint32_t> cube = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                      2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  std::vector<double> withDuplicate = corners;
  withDuplicate.insert(withDuplicate.end(), {-1, -1, -1});   // vertex 8: vertex 0 again
  std::vector<uint32_t> withCollapsed = cube;
  withCollapsed.insert(withCollapsed.end(), {0, 8, 1});     // along the cube's edge 0-1
  const Mesh clean = sffd::testing::meshFromArrays(corners, cube);
  const Mesh odd = sffd::testing::meshFromArrays(withDuplicate, withCollapsed);
  const Lattice identity = fitLattice(clean);
  Device device = openDevice("cpu");
  for (Method method : {Method::Smooth, Method::Accurate}) {
    SCOPED_TRACE(nameOf(method));
    DeformOptions o = strictOptions(method);
    Deformer a(device, clean, identity, o), b(device, odd, identity, o);
    a.deform(identity);
    b.deform(identity);
    const Mesh want = a.result(), got = b.result();
    EXPECT_EQ(got.triangles.size(), want.triangles.size());
    auto offTheCube = [](const Mesh& m) {   // the largest distance of a vertex from the cube's surface
      double off = 0;
      for (const glm::dvec3& p : m.positions)
        off = std::max(off, std::min({std::abs(1 - std::abs(p.x)), std::abs(1 - std::abs(p.y)), std::abs(1 - std::abs(p.z))}));
      return off;
    };
    EXPECT_LT(offTheCube(want), 1e-5);   // float rounding
    EXPECT_EQ(offTheCube(got), offTheCube(want));
  }
}


}  // namespace
