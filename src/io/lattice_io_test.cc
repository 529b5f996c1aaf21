// Lattice files (lattice_io.h): PyGeM .prm against PyGeM's own numbers (case.txt), .npy from the
// reference implementation, the JSON format (round trip, errors with lines), and the presets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <sstream>

#include <sffd/error.h>
#include "tests/support/temp_folder_test.h"
#include "io/lattice_io.h"

using namespace sffd;
namespace fs = std::filesystem;

namespace {

const std::string kData = SFFD_TEST_DATA;

class LatticeIo : public sffd::test::TempFolderTest {
 protected:
  size_t fileCount() const { return size_t(std::distance(fs::directory_iterator(dir_), fs::directory_iterator())); }
};

using sffd::test::expectInputError;

// ---------------------------------------------------------------------------------------------------
// PyGeM .prm

struct CaseTxt {
  glm::dvec3 edges[3];   // columns of A
  struct Point {
    int i, j, k;
    glm::dvec3 undeformed, deformed;
  };
  std::vector<Point> points;
};

CaseTxt readCase(const std::string& file) {
  CaseTxt c;
  std::ifstream in(file);
  std::string line;
  bool inPoints = false;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string head;
    ss >> head;
    if (head == "ex:" || head == "ey:" || head == "ez:") {
      int a = head[1] - 'x';
      ss >> c.edges[a].x >> c.edges[a].y >> c.edges[a].z;
    } else if (head == "i" && line.find("undeformed_x") != std::string::npos) {
      inPoints = true;
    } else if (inPoints && !head.empty()) {
      CaseTxt::Point p;
      p.i = std::stoi(head);
      ss >> p.j >> p.k >> p.undeformed.x >> p.undeformed.y >> p.undeformed.z >> p.deformed.x >> p.deformed.y >> p.deformed.z;
      c.points.push_back(p);
    }
  }
  return c;
}

void checkPrmAgainstCase(const std::string& prm, const std::string& caseFile) {
  SCOPED_TRACE(prm);
  Lattice L = readLattice(prm);
  CaseTxt c = readCase(caseFile);
  ASSERT_EQ(c.points.size(), 12u);
  EXPECT_EQ(L.counts, (std::array<int, 3>{3, 2, 2}));
  EXPECT_EQ(L.degree, (std::array<int, 3>{2, 1, 1}));
  EXPECT_EQ(L.knots[0], (std::vector<double>{0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(L.knots[1], (std::vector<double>{0, 0, 1, 1}));
  EXPECT_EQ(L.outside, OutsideMode::Keep);
  glm::dmat3 A = glm::inverse(L.frameLinear);
  for (int a = 0; a < 3; ++a)
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(A[a][r], c.edges[a][r], 1e-12 * 90);
  for (const auto& p : c.points) {
    glm::dvec3 got = L.controlPoints[L.index(p.i, p.j, p.k)];
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], p.deformed[a], 1e-12 * std::max(1.0, std::abs(p.deformed[a])));
    // The frame maps the undeformed lattice point to its Bernstein parameter (i/2, j, k).
    glm::dvec3 s = L.frameLinear * p.undeformed + L.frameOffset;
    EXPECT_NEAR(s.x, p.i / 2.0, 1e-13);
    EXPECT_NEAR(s.y, p.j, 1e-13);
    EXPECT_NEAR(s.z, p.k, 1e-13);
  }
}

TEST_F(LatticeIo, PrmMatchesPyGeM) {
  checkPrmAgainstCase(kData + "/pygem/sphere_ffd/parameters_test_ffd_sphere.prm", kData + "/pygem/sphere_ffd/case.txt");
  checkPrmAgainstCase(kData + "/pygem/rotation_convention/parameters_sphere.prm", kData + "/pygem/rotation_convention/case.txt");
  checkPrmAgainstCase(kData + "/pygem/identity/parameters_test_ffd_identity.prm", kData + "/pygem/identity/case.txt");
}

TEST_F(LatticeIo, PrmIdentityIsUndeformed) {
  Lattice L = readLattice(kData + "/pygem/identity/parameters_test_ffd_identity.prm");
  CaseTxt c = readCase(kData + "/pygem/identity/case.txt");
  for (const auto& p : c.points) {
    glm::dvec3 got = L.controlPoints[L.index(p.i, p.j, p.k)];
    EXPECT_LT(glm::length(got - p.undeformed), 1e-12 * 100);
  }
  // Reading a setIdentityControlPoints lattice with the same frame gives the same points.
  Lattice I = L;
  setIdentityControlPoints(I);
  for (size_t i = 0; i < L.controlPoints.size(); ++i) EXPECT_LT(glm::length(I.controlPoints[i] - L.controlPoints[i]), 1e-12 * 100);
}


// The PyGeM parameters (what the Python package's sffd.FFD holds): the file's values exactly, the
// same lattice as readLattice, written and read back to the same values.
TEST_F(LatticeIo, PygemParametersRoundTrip) {
  const std::string prm = kData + "/pygem/rotation_convention/parameters_sphere.prm";
  PygemParameters P = readPygemParameters(prm);
  EXPECT_EQ(P.counts, (std::array<int, 3>{3, 2, 2}));
  EXPECT_EQ(P.angleDeg, glm::dvec3(20.3, 11.0, 0.0));
  ASSERT_EQ(P.mu.size(), 12u);
  EXPECT_EQ(P.mu[(0 * 2 + 1) * 2 + 1], glm::dvec3(0.0, 0.0, -0.456229852));
  Lattice A = pygemLattice(P), B = readLattice(prm);
  EXPECT_EQ(A.controlPoints, B.controlPoints);
  EXPECT_TRUE(sameLatticeStructure(A, B));
  writePygemParameters(path("again.prm"), P);
  PygemParameters Q = readPygemParameters(path("again.prm"));
  EXPECT_EQ(Q.mu, P.mu);
  EXPECT_EQ(Q.origin, P.origin);
  EXPECT_EQ(Q.length, P.length);
  EXPECT_EQ(Q.angleDeg, P.angleDeg);
  P.counts[0] = 7;
  expectInputError([&] { pygemLattice(P); }, "PyGeM parameters", 0, "2..6 are supported");
  expectInputError([&] { readPygemParameters(path("missing.prm")); }, path("missing.prm"), 0, "");
}
TEST_F(LatticeIo, PrmSyntax) {
  // "key = value", keys in any case, values on the key line, comments, a repeated entry overrides.
  std::string prm =
      "[Box info]\nN control points x = 2\nn control points y: 2\nn control points z: 2\n"
      "box length x: 2\nbox length y: 2\nbox length z: 2\nbox origin x: -1\nbox origin y: -1\nbox origin z: -1\n"
      "rotation angle x: 0\nrotation angle y: 0\nrotation angle z: 0\n\n"
      "[Parameters weights]\nparameter x: 1 1 1 0.5\n\n   1 1 1 0.25\n; comment\nparameter y:\nparameter z: 0 0 0 -.5\n";
  Lattice L = readLattice(write("ok.prm", prm));
  EXPECT_EQ(L.controlPoints[L.index(1, 1, 1)], glm::dvec3(1.5, 1, 1));
  EXPECT_EQ(L.controlPoints[L.index(0, 0, 0)], glm::dvec3(-1, -1, -2));
  EXPECT_EQ(L.controlPoints[L.index(1, 0, 0)], glm::dvec3(1, -1, -1));

  std::string good = prm;
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  };
  expectInputError([&] { readLattice(write("a.prm", with("[Parameters weights]", "[Weights]"))); }, path("a.prm"), 0,
                   "missing section [Parameters weights]");
  expectInputError([&] { readLattice(write("b.prm", with("box length y: 2\n", ""))); }, path("b.prm"), 1,
                   "missing key 'box length y'");
  expectInputError([&] { readLattice(write("c.prm", with("box origin y: -1", "box origin y: abc"))); }, path("c.prm"), 9,
                   "bad number");
  expectInputError([&] { readLattice(write("d.prm", with("1 1 1 0.5", "1 2 1 0.5"))); }, path("d.prm"), 16, "out of range");
  expectInputError([&] { readLattice(write("e.prm", with("1 1 1 0.5", "1 1 0.5"))); }, path("e.prm"), 16, "expected 'i j k value'");
  expectInputError([&] { readLattice(write("f.prm", with("n control points y: 2", "n control points y: 1"))); }, path("f.prm"), 3,
                   "2..6");
  expectInputError([&] { readLattice(write("g.prm", with("box length z: 2", "box length z: 0"))); }, path("g.prm"), 7,
                   "positive");
  expectInputError([&] { readLattice(write("h.prm", with("box length z: 2", "box length z: 2\nbox length z: 3"))); }, path("h.prm"), 8,
                   "appears twice");
  expectInputError([&] { readLattice(write("i.prm", "just text\n")); }, path("i.prm"), 1, "expected 'key: value'");
  expectInputError([&] { readLattice(write("j.prm", with("0 0 0 -.5", "0 0 0 nan"))); }, path("j.prm"), 21, "non-finite");
}

// ---------------------------------------------------------------------------------------------------
// .npy

std::string npyBytes(const std::string& header, const std::string& data, int version = 1) {
  std::string h = header;
  size_t pre = version == 1 ? 10 : 12;
  while ((pre + h.size() + 1) % 64) h += ' ';
  h += '\n';
  std::string s = "\x93NUMPY";
  s += char(version);
  s += '\0';
  if (version == 1) {
    s += char(h.size() & 0xff);
    s += char(h.size() >> 8);
  } else {
    for (int b = 0; b < 4; ++b) s += char((h.size() >> (8 * b)) & 0xff);
  }
  return s + h + data;
}

template <typename T>
std::string rawValues(const std::vector<T>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

LatticeReadOptions boxOptions(glm::dvec3 lo, glm::dvec3 hi) {
  LatticeReadOptions o;
  o.haveMeshBox = true;
  o.meshBoxLo = lo;
  o.meshBoxHi = hi;
  return o;
}

// The identity .npy of a .bpt model is the Greville lattice of the model's box (tessellated 10 x 10 a
// patch) normalised so that its largest half-extent is 1 -- not 0.99: the reference implementation's
// body box is the model's box in [-1,1]^3, the model itself then being scaled by 0.99 inside it.
void expectGrevilleNpy(const std::string& npy, const std::string& bpt) {
  Mesh teapot = readMesh(bpt);
  glm::dvec3 lo(1e9), up(-1e9);
  for (const auto& p : teapot.positions) lo = glm::min(lo, p), up = glm::max(up, p);
  glm::dvec3 centre = 0.5 * (lo + up);
  double half = 0.5 * std::max({up.x - lo.x, up.y - lo.y, up.z - lo.z});
  lo = (lo - centre) / half;
  up = (up - centre) / half;
  Lattice L = readLattice(npy, boxOptions(lo, up));
  EXPECT_EQ(L.counts, (std::array<int, 3>{5, 5, 5}));
  EXPECT_EQ(L.degree, (std::array<int, 3>{2, 2, 2}));
  EXPECT_EQ(L.knots[0], clampedUniformKnots(5, 2, lo.x, up.x));
  EXPECT_EQ(L.frameLinear, glm::dmat3(1.0));
  Lattice I = L;
  setIdentityControlPoints(I);
  for (size_t i = 0; i < L.controlPoints.size(); ++i) EXPECT_LT(glm::length(L.controlPoints[i] - I.controlPoints[i]), 2e-7) << i;
  // Point [i][j][k] has i along x: Greville points {-1, -2/3, 0, 2/3, 1} of the box.
  EXPECT_NEAR(L.controlPoints[L.index(1, 0, 0)].x, -2.0 / 3.0, 1e-7);
  EXPECT_NEAR(L.controlPoints[L.index(0, 3, 0)].y, 2.0 / 3.0 * up.y, 1e-7);
  EXPECT_NEAR(L.controlPoints[L.index(0, 0, 2)].z, 0.0, 1e-7);
}

// A deformed lattice over [-1,1]^3: its unmoved points are Greville points there.
int unmovedNpyPoints(const std::string& npy) {
  Lattice C = readLattice(npy, boxOptions(glm::dvec3(-1), glm::dvec3(1)));
  Lattice CI = C;
  setIdentityControlPoints(CI);
  int unmoved = 0;
  for (size_t i = 0; i < C.controlPoints.size(); ++i) unmoved += glm::length(C.controlPoints[i] - CI.controlPoints[i]) < 1e-6;
  EXPECT_EQ(C.controlPoints[0], glm::dvec3(-1, -1, -1));
  return unmoved;
}

TEST_F(LatticeIo, NpyReferenceFiles) {
  expectGrevilleNpy(kData + "/lattices/teapot_identity.npy", kData + "/teapot.bpt");
  // cube2_top moves the 9 interior points of the top layer only (tools/make_test_data.py).
  EXPECT_EQ(unmovedNpyPoints(kData + "/lattices/cube2_top.npy"), 125 - 9);
  // Every .npy of the test data reads (float32 (5,5,5,3)); the degree comes from the options.
  LatticeReadOptions o = boxOptions(glm::dvec3(-1), glm::dvec3(1));
  o.npyDegree = {3, 2, 1};
  int files = 0;
  for (const auto& e : fs::directory_iterator(kData + "/lattices")) {
    Lattice X = readLattice(e.path().string(), o);
    EXPECT_EQ(X.pointCount(), 125u);
    EXPECT_EQ(X.degree, o.npyDegree);
    EXPECT_EQ(X.knots[0].size(), 9u);
    ++files;
  }
  EXPECT_GE(files, 7);
}

// The reference implementation's own files, where SFFD_REFERENCE_DATA names a copy (tests/data/README.md).
TEST_F(LatticeIo, NpyFilesOfTheReferenceImplementation) {
  const char* ref = std::getenv("SFFD_REFERENCE_DATA");
  if (!ref) GTEST_SKIP() << "SFFD_REFERENCE_DATA not set: the reference implementation's .npy files are not in the repository";
  const std::string d = std::string(ref) + "/acaffd/";
  expectGrevilleNpy(d + "lattices/t_control_points0.npy", d + "t.bpt");
  EXPECT_EQ(unmovedNpyPoints(d + "lattices/cube2_control_points0.npy"), 44);
}

TEST_F(LatticeIo, NpyFloat64AndVersion2) {
  std::vector<double> v(2 * 2 * 2 * 3);
  for (size_t i = 0; i < v.size(); ++i) v[i] = 0.1 * double(i);
  std::string p = write("d.npy", npyBytes("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2, 2, 3), }", rawValues(v), 2));
  LatticeReadOptions o = boxOptions(glm::dvec3(0), glm::dvec3(1));
  o.npyDegree = {1, 1, 1};
  Lattice L = readLattice(p, o);
  EXPECT_EQ(L.controlPoints[L.index(1, 0, 1)], glm::dvec3(v[15], v[16], v[17]));   // (1*2+0)*2+1 = 5
}

TEST_F(LatticeIo, NpyBadFiles) {
  std::vector<float> ok(5 * 5 * 5 * 3, 0.5f);
  const std::string hdr = "{'descr': '<f4', 'fortran_order': False, 'shape': (5, 5, 5, 3), }";
  LatticeReadOptions o = boxOptions(glm::dvec3(-1), glm::dvec3(1));
  struct Case {
    const char* name;
    std::string bytes;
    const char* part;
  };
  std::vector<float> nan = ok;
  nan[7] = NAN;
  std::vector<Case> cases = {
      {"fortran.npy", npyBytes("{'descr': '<f4', 'fortran_order': True, 'shape': (5, 5, 5, 3), }", rawValues(ok)), "Fortran"},
      {"big.npy", npyBytes("{'descr': '>f4', 'fortran_order': False, 'shape': (5, 5, 5, 3), }", rawValues(ok)), "big-endian"},
      {"int.npy", npyBytes("{'descr': '<i4', 'fortran_order': False, 'shape': (5, 5, 5, 3), }", rawValues(ok)), "dtype '<i4'"},
      {"shape3.npy", npyBytes("{'descr': '<f4', 'fortran_order': False, 'shape': (5, 5, 15), }", rawValues(ok)), "(5, 5, 15)"},
      {"shape2.npy", npyBytes("{'descr': '<f4', 'fortran_order': False, 'shape': (5, 5, 5, 2), }", rawValues(ok)), "not (mu, mv, mw, 3)"},
      {"huge.npy", npyBytes("{'descr': '<f4', 'fortran_order': False, 'shape': (4000, 4000, 4000, 3), }", rawValues(ok)), "too large"},
      {"trunc.npy", npyBytes(hdr, rawValues(ok).substr(0, 100)), "truncated .npy data"},
      {"magic.npy", "NUMPY but not", "not a .npy file"},
      {"hdrlen.npy", std::string("\x93NUMPY\x01\x00\xff\xff{", 11), "truncated .npy header"},
      {"hdrsyntax.npy", npyBytes("{'descr' '<f4'}", rawValues(ok)), "bad .npy header"},
      {"nan.npy", npyBytes(hdr, rawValues(nan)), "not finite"},
      {"few.npy", npyBytes("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 5, 5, 3), }", rawValues(ok).substr(0, 600)),
       "too few for degree 2"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::string p = write(c.name, c.bytes);
    expectInputError([&] { readLattice(p, o); }, p, 0, c.part);
  }
  std::string p = write("ok.npy", npyBytes(hdr, rawValues(ok)));
  expectInputError([&] { readLattice(p); }, p, 0, "no box");
  EXPECT_NO_THROW(readLattice(p, o));
}

// ---------------------------------------------------------------------------------------------------
// JSON

void expectSameLattice(const Lattice& a, const Lattice& b) {
  EXPECT_EQ(a.degree, b.degree);
  EXPECT_EQ(a.counts, b.counts);
  for (int x = 0; x < 3; ++x) EXPECT_EQ(a.knots[x], b.knots[x]);
  EXPECT_EQ(a.controlPoints, b.controlPoints);
  EXPECT_EQ(a.frameLinear, b.frameLinear);
  EXPECT_EQ(a.frameOffset, b.frameOffset);
  EXPECT_EQ(a.outside, b.outside);
}

TEST_F(LatticeIo, JsonRoundTripIsExact) {
  Lattice L = makeIdentityLattice({-1.1, -0.7, -1.0 / 3.0}, {1.3, 0.9, 2.0 / 3.0}, {5, 6, 4}, {2, 3, 1});
  applyLatticePreset(L, "noise", 1.0);
  writeLatticeJson(path("a.json"), L);
  expectSameLattice(L, readLattice(path("a.json")));
  // No "knots" for clamped uniform ones.
  {
    std::ifstream in(path("a.json"));
    std::string s(std::istreambuf_iterator<char>(in), {});
    EXPECT_EQ(s.find("\"knots\""), std::string::npos);
    EXPECT_NE(s.find("\"outside\": \"extrapolate\""), std::string::npos);
  }
  // Non-uniform knots on one axis, "keep".
  L.knots[1] = {-0.7, -0.7, -0.7, -0.7, 0.1, 0.15, 0.9, 0.9, 0.9, 0.9};
  L.outside = OutsideMode::Keep;
  writeLatticeJson(path("b.json"), L);
  expectSameLattice(L, readLattice(path("b.json")));
  // A PyGeM lattice keeps its rotated frame.
  Lattice P = readLattice(kData + "/pygem/sphere_ffd/parameters_test_ffd_sphere.prm");
  writeLatticeJson(path("p.json"), P);
  expectSameLattice(P, readLattice(path("p.json")));
}

TEST_F(LatticeIo, JsonDefaults) {
  std::string base = R"({"format": "sffd-lattice", "version": 1, "degree": [2, 2, 2], "counts": [5, 5, 5],
 "box": {"min": [-1, -1, -1], "max": [1, 1, 1]})";
  Lattice L = readLattice(write("min.json", base + "}"));
  Lattice I = makeIdentityLattice(glm::dvec3(-1), glm::dvec3(1), {5, 5, 5}, {2, 2, 2});
  expectSameLattice(L, I);
  EXPECT_LT(glm::length(L.controlPoints[L.index(1, 2, 3)] - glm::dvec3(-2.0 / 3.0, 0.0, 2.0 / 3.0)), 1e-15);
  // Empty knot vectors are the default; comments are allowed; displacements add to the identity.
  std::string disp = base + ", // a comment\n \"knots\": {\"u\": [], \"v\": [], \"w\": []}, \"outside\": \"keep\", \"displacements\": [";
  for (int i = 0; i < 125; ++i) disp += std::string(i ? ", " : "") + (i == 62 ? "[0.5, 0, -0.25]" : "[0, 0, 0]");
  Lattice D = readLattice(write("disp.json", disp + "]}"));
  EXPECT_EQ(D.outside, OutsideMode::Keep);
  EXPECT_EQ(D.controlPoints[62], I.controlPoints[62] + glm::dvec3(0.5, 0, -0.25));   // the centre point (2,2,2) moved
  EXPECT_EQ(D.controlPoints[61], I.controlPoints[61]);
}

TEST_F(LatticeIo, JsonErrorsHaveLines) {
  auto lines = [](std::initializer_list<std::string> l) {
    std::string s;
    for (const auto& x : l) s += x + "\n";
    return s;
  };
  std::string pts7;   // 7 good points, one a line
  for (int i = 0; i < 7; ++i) pts7 += std::string(i ? ",\n" : "") + "  [0, 0, 0]";
  auto doc = [&](const std::string& degree, const std::string& counts, const std::string& box, const std::string& extra) {
    return lines({"{", "\"format\": \"sffd-lattice\",", "\"version\": 1,", "\"degree\": " + degree + ",", "\"counts\": " + counts + ",",
                  "\"box\": " + box + extra, "}"});
  };
  const std::string box = "{\"min\": [0, 0, 0], \"max\": [1, 1, 1]}";
  struct Case {
    const char* name;
    std::string text;
    size_t line;
    const char* part;
  };
  std::vector<Case> cases = {
      {"syntax.json", lines({"{", "\"format\": \"sffd-lattice\",", "\"version\": 1,", "\"degree\": [1, 1, 1]", "\"counts\": [2, 2, 2]", "}"}),
       5, "JSON syntax error"},
      {"eof.json", lines({"{", "\"format\": \"sffd-lattice\","}), 3, "JSON syntax error"},
      {"notobj.json", "[1, 2]", 1, "expected a JSON object"},
      {"format.json", lines({"{", "\"format\": \"other\"", "}"}), 2, "format must be"},
      {"missing.json", lines({"{", "\"format\": \"sffd-lattice\",", "\"version\": 1", "}"}), 0, "missing field \"degree\""},
      {"version.json", lines({"{", "\"format\": \"sffd-lattice\",", "\"version\": 2", "}"}), 3, "unsupported version"},
      {"degree.json", doc("[1, 1, 2]", "[2, 2, 2]", box, ""), 5, "counts must exceed the degree"},
      {"degree6.json", doc("[1, 1, 6]", "[2, 2, 9]", box, ""), 4, "1..5"},
      {"degreef.json", doc("[1, 1, 1.5]", "[2, 2, 2]", box, ""), 4, "3 integers"},
      {"box.json", doc("[1, 1, 1]", "[2, 2, 2]", "{\"min\": [0, 0, 0], \"max\": [1, 0, 1]}", ""), 6, "zero-size"},
      {"inf.json", doc("[1, 1, 1]", "[2, 2, 2]", "{\"min\": [0, 0, 0], \"max\": [1, 1e999, 1]}", ""), 6, "number overflow"},
      {"count.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"control_points\": [\n  [0, 0, 0]\n]"), 7, "has 1 points"},
      {"point.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"control_points\": [\n" + pts7 + ",\n  [0, \"x\", 0]\n]"),
       15, "control_points[7]"},
      {"both.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"control_points\": [],\n\"displacements\": []"), 8, "not both"},
      {"knots.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"knots\": {\"u\": [0, 0, 1, 0.5]}"), 7, "non-decreasing"},
      {"knotn.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"knots\": {\n\"v\": [0, 0, 1]}"), 8, "counts+degree+1"},
      {"knotbox.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"knots\": {\"w\": [0, 0, 2, 2]}"), 7, "but the box spans"},
      {"unknown.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"controlpoints\": []"), 7, "unknown field \"controlpoints\""},
      {"twice.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"degree\": [2, 2, 2]"), 7, "the key 'degree' is given twice in one object"},
      {"outside.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"outside\": \"wrap\""), 7, "extrapolate"},
      {"huge.json", doc("[1, 1, 1]", "[4000, 4000, 4000]", box, ""), 5, "too large"},
      {"frame.json", doc("[1, 1, 1]", "[2, 2, 2]", box, ",\n\"frame\": {\"matrix\": [[1, 0, 0], [0, 1, 0], [1, 0, 0]]}"), 7, "singular"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::string p = write(c.name, c.text);
    expectInputError([&] { readLattice(p); }, p, c.line, c.part);
  }
  expectInputError([&] { readLattice(path("none.json")); }, path("none.json"), 0, "No such file");
  expectInputError([&] { readLattice(write("lat.txt", "x")); }, path("lat.txt"), 0, "unknown lattice format");
  expectInputError([&] { readLattice(write("empty.json", "")); }, path("empty.json"), 0, "empty file");
}

TEST_F(LatticeIo, FailedWriteLeavesNothing) {
  Lattice L = makeIdentityLattice(glm::dvec3(0), glm::dvec3(1), {3, 3, 3}, {2, 2, 2});
  L.controlPoints[4].y = NAN;
  EXPECT_THROW(writeLatticeJson(path("bad.json"), L), Error);
  EXPECT_EQ(fileCount(), 0u);
}

// ---------------------------------------------------------------------------------------------------
// Presets

TEST_F(LatticeIo, Presets) {
  const glm::dvec3 lo(-2, -1, -0.5), hi(2, 1, 0.5);   // longest axis x, then y
  Lattice I = makeIdentityLattice(lo, hi, {5, 5, 5}, {2, 2, 2});
  for (const char* name : {"twist", "bend", "taper", "bulge", "noise"}) {
    SCOPED_TRACE(name);
    Lattice a = I, b = I, z = I;
    applyLatticePreset(a, name, 1.0);
    applyLatticePreset(b, name, 1.0);
    applyLatticePreset(z, name, 0.0);
    EXPECT_EQ(a.controlPoints, b.controlPoints);   // deterministic
    double moved = 0;
    for (size_t i = 0; i < I.controlPoints.size(); ++i) {
      moved = std::max(moved, glm::length(a.controlPoints[i] - I.controlPoints[i]));
      EXPECT_LT(glm::length(z.controlPoints[i] - I.controlPoints[i]), 1e-15);
    }
    EXPECT_GT(moved, 0.05);
    EXPECT_NO_THROW(validateLattice(a, "preset"));
  }
  auto at = [&](const Lattice& L, int i, int j, int k) { return L.controlPoints[L.index(i, j, k)]; };
  Lattice t = I;
  applyLatticePreset(t, "twist", 1.0);
  // About x: the x = +2 end turns +45 degrees, the middle stays, distances to the axis are kept.
  glm::dvec3 p = at(t, 4, 4, 2), q = at(I, 4, 4, 2);
  EXPECT_NEAR(p.x, q.x, 1e-15);
  EXPECT_NEAR(std::hypot(p.y, p.z), std::hypot(q.y, q.z), 1e-14);
  EXPECT_NEAR(std::atan2(p.z, p.y) - std::atan2(q.z, q.y), std::numbers::pi / 4, 1e-14);
  EXPECT_LT(glm::length(at(t, 2, 4, 4) - at(I, 2, 4, 4)), 1e-15);
  Lattice tp = I;
  applyLatticePreset(tp, "taper", 1.0);
  EXPECT_NEAR(at(tp, 4, 4, 4).y, 0.5, 1e-15);   // halved at the high end
  EXPECT_NEAR(at(tp, 0, 4, 4).y, 1.0, 1e-15);
  Lattice bd = I;
  applyLatticePreset(bd, "bend", 1.0);
  EXPECT_NEAR(at(bd, 0, 2, 2).y, 0.5, 1e-15);   // ends move by h_y / 2 toward +y
  EXPECT_NEAR(at(bd, 2, 2, 2).y, 0.0, 1e-15);
  Lattice bg = I;
  applyLatticePreset(bg, "bulge", 1.0);
  EXPECT_NEAR(at(bg, 2, 4, 0).y, 1.5, 1e-15);   // middle grows by 1 + a/2
  EXPECT_NEAR(at(bg, 0, 4, 0).y, 1.0, 1e-15);
  Lattice n = I;
  applyLatticePreset(n, "noise", 1.0);
  for (size_t i = 0; i < n.controlPoints.size(); ++i) {
    glm::dvec3 d = glm::abs(n.controlPoints[i] - I.controlPoints[i]);
    EXPECT_LE(d.x, 0.4);
    EXPECT_LE(d.y, 0.2);
    EXPECT_LE(d.z, 0.1);
  }
  // A rotated PyGeM box: presets work in its own axes.
  Lattice P = readLattice(kData + "/pygem/identity/parameters_test_ffd_identity.prm");
  EXPECT_NO_THROW(applyLatticePreset(P, "twist", 0.5));
  EXPECT_THROW(applyLatticePreset(P, "wobble", 1.0), Error);
  try {
    applyLatticePreset(P, "wobble", 1.0);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
  }
}

// A cube's box, fitted where it lies: its sides differ by the rounding of its corners, which grows with the
// distance from the origin; the preset must act on the same axes wherever the cube is (the twist's axis
// turned from x to another when a side came out an ulp longer: control points 0.65 apart).
TEST_F(LatticeIo, PresetAxesDoNotTurnWithTheBoxsRounding) {
  const glm::dvec3 lo(-1.01, -1.01, -1.01), hi(1.01, 1.01, 1.01);   // fitLattice's box of the unit sphere
  Lattice here = makeIdentityLattice(lo, hi, {5, 5, 5}, {2, 2, 2});
  for (const glm::dvec3 offset : {glm::dvec3(10, 0, 0), glm::dvec3(1e7, -3e7, 5e6), glm::dvec3(0.1, 0.7, 1e9)}) {
    SCOPED_TRACE(offset.x);
    Lattice there = makeIdentityLattice(lo + offset, hi + offset, {5, 5, 5}, {2, 2, 2});
    for (const char* name : {"twist", "bend", "taper", "bulge"}) {
      Lattice a = here, b = there;
      applyLatticePreset(a, name, 0.5);
      applyLatticePreset(b, name, 0.5);
      double apart = 0;
      for (size_t i = 0; i < a.controlPoints.size(); ++i)
        apart = std::max(apart, glm::length((b.controlPoints[i] - offset) - a.controlPoints[i]));
      EXPECT_LT(apart, 1e-6 * (1 + glm::length(offset)) * 1e-6) << name;
    }
  }
}

}  // namespace
