// PyGeM .prm and reference-implementation .npy lattice files.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <numbers>

#include <sffd/error.h>
#include "io/atomic_file.h"
#include "io/io_util.h"
#include "io/lattice_io_internal.h"

namespace sffd::latticeio {

// ---------------------------------------------------------------------------------------------------
// PyGeM .prm (mathLab/PyGeM pygem/ffd.py, read with Python's configparser): sections [Box info] and
// [Parameters weights]. Keys (case-insensitive, "key: value" or "key = value"): n control points x/y/z,
// box length x/y/z, box origin x/y/z, rotation angle x/y/z (degrees), and parameter x/y/z, whose value
// (continued on indented lines) holds "i j k mu" lines, mu the displacement normalised by the box length,
// in the box's local axes; absent entries are 0.
// Meaning (METHOD.md 6): a Bernstein lattice, i.e. one knot box of degree n-1 on each axis with knots
// [0..0, 1..1] in the parameter space [0,1]^3; R = Rx(ax) Ry(ay) Rz(az), A = R diag(L), parameter of a
// world point x: p = A^-1 (x - origin); control point (i, j, k) = origin + A ((i/(nx-1), j/(ny-1),
// k/(nz-1)) + mu_ijk); points outside the box are left unmoved (OutsideMode::Keep).

namespace {

struct IniValue {
  size_t line = 0;                                          // the key's line
  std::vector<std::pair<std::string_view, size_t>> lines;   // value lines (the first is the rest of the key's line)
};
struct IniSection {
  size_t line = 0;
  std::map<std::string, IniValue> values;
};

// configparser's rules, as PyGeM uses them: full-line comments start with '#' or ';' (and end a value's
// continuation), a line indented deeper than its key continues the value, blank lines do not end it,
// duplicate sections or keys are errors.
std::map<std::string, IniSection> parseIni(const std::string& path, const std::string& text) {
  std::map<std::string, IniSection> sections;
  IniSection* cur = nullptr;
  IniValue* value = nullptr;
  size_t valueIndent = 0;
  io::LineReader lines(text);
  std::string_view l;
  size_t line = 0;
  while (lines.next(l, line)) {
    std::string_view t = io::trim(l);
    if (t.empty()) continue;
    if (t[0] == '#' || t[0] == ';') {
      value = nullptr;
      continue;
    }
    size_t indent = size_t(std::find_if(l.begin(), l.end(), [](char c) { return c != ' ' && c != '\t'; }) - l.begin());
    if (value && indent > valueIndent) {
      value->lines.push_back({t, line});
      continue;
    }
    value = nullptr;
    if (t.front() == '[' && t.back() == ']' && t.size() > 2) {
      std::string name(io::trim(t.substr(1, t.size() - 2)));
      auto [it, isNew] = sections.emplace(name, IniSection{});
      if (!isNew) throw inputError(path, line, "section " + io::quoted("[" + name + "]") + " appears twice");
      it->second.line = line;
      cur = &it->second;
      continue;
    }
    size_t d = t.find_first_of(":=");
    if (d == std::string_view::npos) throw inputError(path, line, "expected 'key: value' or a [section], found " + io::quoted(t));
    if (!cur) throw inputError(path, line, "'key: value' line before any [section]");
    std::string key(io::trim(t.substr(0, d)));
    for (char& c : key) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (key.empty()) throw inputError(path, line, "empty key");
    auto [it, isNew] = cur->values.emplace(key, IniValue{});
    if (!isNew) throw inputError(path, line, "key " + io::quoted(key) + " appears twice in its section");
    it->second.line = line;
    std::string_view rest = io::trim(t.substr(d + 1));
    if (!rest.empty()) it->second.lines.push_back({rest, line});
    value = &it->second;
    valueIndent = indent;
  }
  return sections;
}

glm::dmat3 rotationX(double a) {   // glm is column-major: m[col][row]
  glm::dmat3 m(1.0);
  m[1][1] = std::cos(a), m[2][1] = -std::sin(a);
  m[1][2] = std::sin(a), m[2][2] = std::cos(a);
  return m;
}
glm::dmat3 rotationY(double a) {
  glm::dmat3 m(1.0);
  m[0][0] = std::cos(a), m[2][0] = std::sin(a);
  m[0][2] = -std::sin(a), m[2][2] = std::cos(a);
  return m;
}
glm::dmat3 rotationZ(double a) {
  glm::dmat3 m(1.0);
  m[0][0] = std::cos(a), m[1][0] = -std::sin(a);
  m[0][1] = std::sin(a), m[1][1] = std::cos(a);
  return m;
}

}  // namespace

PygemParameters parsePrm(const std::string& path, const std::string& text) {
  auto sections = parseIni(path, text);
  auto section = [&](const char* name) -> IniSection& {
    auto it = sections.find(name);
    if (it == sections.end()) throw inputError(path, 0, std::string("missing section [") + name + "]");
    return it->second;
  };
  IniSection& box = section("Box info");
  IniSection& weights = section("Parameters weights");
  auto get = [&](IniSection& s, const char* sname, const std::string& key) -> IniValue& {
    auto it = s.values.find(key);
    if (it == s.values.end()) throw inputError(path, s.line, "missing key '" + key + "' in [" + sname + "]");
    return it->second;
  };
  auto scalar = [&](const std::string& key) {
    IniValue& v = get(box, "Box info", key);
    if (v.lines.size() != 1) throw inputError(path, v.line, "'" + key + "' needs one number");
    double d = 0;
    if (!io::parseDouble(v.lines[0].first, d)) throw inputError(path, v.line, "'" + key + "': bad number " + io::quoted(v.lines[0].first));
    if (!std::isfinite(d)) throw inputError(path, v.line, "'" + key + "' is not finite");
    return d;
  };
  static const char xyz[] = "xyz";
  std::array<int, 3> n{};
  glm::dvec3 length, origin, angle;
  for (int a = 0; a < 3; ++a) {
    std::string key = std::string("n control points ") + xyz[a];
    IniValue& v = get(box, "Box info", key);
    long long c = 0;
    if (v.lines.size() != 1 || !io::parseInt(v.lines[0].first, c)) throw inputError(path, v.line, "'" + key + "' needs an integer");
    if (c < 2 || c > 6)
      throw inputError(path, v.line, "'" + key + "' is " + std::to_string(c) + "; 2..6 are supported (degree = count - 1, 1..5)");
    n[a] = int(c);
    length[a] = scalar(std::string("box length ") + xyz[a]);
    if (!(length[a] > 0)) throw inputError(path, get(box, "Box info", std::string("box length ") + xyz[a]).line, "box length must be positive");
    origin[a] = scalar(std::string("box origin ") + xyz[a]);
    angle[a] = scalar(std::string("rotation angle ") + xyz[a]);
  }

  PygemParameters P;
  P.counts = n, P.length = length, P.origin = origin, P.angleDeg = angle;
  P.mu.assign(size_t(n[0]) * n[1] * n[2], glm::dvec3(0.0));
  for (int a = 0; a < 3; ++a) {
    IniValue& v = get(weights, "Parameters weights", std::string("parameter ") + xyz[a]);
    std::vector<std::string_view> tok;
    for (const auto& [text_, line] : v.lines) {
      io::splitTokens(text_, tok);
      if (tok.size() != 4) throw inputError(path, line, "expected 'i j k value', found " + io::quoted(text_));
      long long idx[3];
      for (int c = 0; c < 3; ++c) {
        if (!io::parseInt(tok[c], idx[c])) throw inputError(path, line, "bad index " + io::quoted(tok[c]));
        if (idx[c] < 0 || idx[c] >= n[c])
          throw inputError(path, line, "index " + std::to_string(idx[c]) + " out of range 0.." + std::to_string(n[c] - 1));
      }
      double d = 0;
      if (!io::parseDouble(tok[3], d)) throw inputError(path, line, "bad number " + io::quoted(tok[3]));
      if (!std::isfinite(d)) throw inputError(path, line, "non-finite value " + io::quoted(tok[3]));
      P.mu[(size_t(idx[0]) * n[1] + size_t(idx[1])) * n[2] + size_t(idx[2])][a] = d;   // a repeated entry overrides, as in PyGeM
    }
  }

  return P;
}

Lattice latticeOfPrm(const PygemParameters& P, const std::string& source) {
  const std::array<int, 3>& n = P.counts;
  for (int a = 0; a < 3; ++a) {
    if (n[a] < 2 || n[a] > 6)
      throw inputError(source, 0, "n control points " + std::to_string(n[a]) + "; 2..6 are supported (degree = count - 1, 1..5)");
    if (!(P.length[a] > 0) || !std::isfinite(P.length[a])) throw inputError(source, 0, "box length must be positive");
    if (!std::isfinite(P.origin[a]) || !std::isfinite(P.angleDeg[a])) throw inputError(source, 0, "box origin or rotation angle not finite");
  }
  Lattice L;
  L.counts = n;
  for (int a = 0; a < 3; ++a) {
    L.degree[a] = n[a] - 1;
    L.knots[a] = clampedUniformKnots(n[a], n[a] - 1, 0.0, 1.0);
  }
  if (!P.mu.empty() && P.mu.size() != L.pointCount())
    throw inputError(source, 0, "mu has " + std::to_string(P.mu.size()) + " entries; the counts need " + std::to_string(L.pointCount()));
  for (const glm::dvec3& m : P.mu)
    if (!std::isfinite(m.x) || !std::isfinite(m.y) || !std::isfinite(m.z)) throw inputError(source, 0, "non-finite mu");
  const glm::dvec3 origin = P.origin;
  const double deg = std::numbers::pi / 180.0;
  glm::dmat3 R = rotationX(P.angleDeg.x * deg) * rotationY(P.angleDeg.y * deg) * rotationZ(P.angleDeg.z * deg);
  glm::dmat3 A = R;
  for (int c = 0; c < 3; ++c) A[c] *= P.length[c];   // A = R diag(L): column c scaled by L_c
  L.frameLinear = glm::inverse(A);
  L.frameOffset = -(L.frameLinear * origin);
  L.controlPoints.resize(L.pointCount());
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k) {
        size_t id = L.index(i, j, k);
        glm::dvec3 s(double(i) / (n[0] - 1), double(j) / (n[1] - 1), double(k) / (n[2] - 1));
        L.controlPoints[id] = origin + A * (s + (P.mu.empty() ? glm::dvec3(0.0) : P.mu[id]));
      }
  L.outside = OutsideMode::Keep;
  validateLattice(L, source);
  return L;
}

Lattice readPrm(const std::string& path, const std::string& text) { return latticeOfPrm(parsePrm(path, text), path); }

// ---------------------------------------------------------------------------------------------------
// .npy (numpy format 1.0/2.0/3.0): a little-endian float32 or float64 array of shape (mu, mv, mw, 3) in
// C order, point [i][j][k] with i along x. The lattice: degree options.npyDegree, clamped uniform knots
// over the mesh box [options.meshBoxLo, options.meshBoxHi], identity frame (the reference
// implementation's convention, METHOD.md 1.1).

namespace {

// A tiny reader for the header's Python dict literal: {'descr': '<f4', 'fortran_order': False, 'shape': (5, 5, 5, 3), }
struct NpyHeader {
  std::string descr;
  bool fortran = false;
  std::vector<long long> shape;
  bool haveDescr = false, haveFortran = false, haveShape = false;
};

NpyHeader parseNpyHeader(const std::string& path, std::string_view h) {
  NpyHeader r;
  size_t i = 0;
  auto fail = [&](const std::string& what) { return inputError(path, 0, "bad .npy header (" + what + "): " + io::quoted(h)); };
  auto ws = [&]() {
    while (i < h.size() && io::isSpace(h[i])) ++i;
  };
  auto expect = [&](char c) {
    ws();
    if (i >= h.size() || h[i] != c) throw fail(std::string("expected '") + c + "'");
    ++i;
  };
  auto str = [&]() {
    ws();
    if (i >= h.size() || (h[i] != '\'' && h[i] != '"')) throw fail("expected a string");
    char q = h[i++];
    size_t s = i;
    while (i < h.size() && h[i] != q) ++i;
    if (i >= h.size()) throw fail("unterminated string");
    return std::string(h.substr(s, i++ - s));
  };
  expect('{');
  while (true) {
    ws();
    if (i < h.size() && h[i] == '}') break;
    std::string key = str();
    expect(':');
    ws();
    if (key == "descr") {
      r.descr = str();
      r.haveDescr = true;
    } else if (key == "fortran_order") {
      if (h.compare(i, 4, "True") == 0) r.fortran = true, i += 4;
      else if (h.compare(i, 5, "False") == 0) r.fortran = false, i += 5;
      else throw fail("fortran_order must be True or False");
      r.haveFortran = true;
    } else if (key == "shape") {
      expect('(');
      while (true) {
        ws();
        if (i < h.size() && h[i] == ')') break;
        size_t s = i;
        while (i < h.size() && std::isdigit(static_cast<unsigned char>(h[i]))) ++i;
        long long v = 0;
        if (!io::parseInt(h.substr(s, i - s), v)) throw fail("bad shape");
        if (i < h.size() && h[i] == 'L') ++i;   // Python 2 long
        r.shape.push_back(v);
        ws();
        if (i < h.size() && h[i] == ',') ++i;
        if (r.shape.size() > 32) throw fail("too many dimensions");
      }
      ++i;
      r.haveShape = true;
    } else {
      throw fail("unknown key " + io::quoted(key));
    }
    ws();
    if (i < h.size() && h[i] == ',') ++i;
  }
  if (!r.haveDescr || !r.haveFortran || !r.haveShape) throw fail("descr, fortran_order and shape are required");
  return r;
}

}  // namespace

Lattice readNpy(const std::string& path, const std::string& text, const LatticeReadOptions& options) {
  if (text.size() < 10 || std::memcmp(text.data(), "\x93NUMPY", 6) != 0) throw inputError(path, 0, "not a .npy file (no \\x93NUMPY magic)");
  const unsigned major = static_cast<unsigned char>(text[6]);
  size_t headerLen = 0, headerStart = 0;
  if (major == 1) {
    headerLen = static_cast<unsigned char>(text[8]) | (size_t(static_cast<unsigned char>(text[9])) << 8);
    headerStart = 10;
  } else if (major == 2 || major == 3) {
    if (text.size() < 12) throw inputError(path, 0, "truncated .npy header");
    for (int b = 0; b < 4; ++b) headerLen |= size_t(static_cast<unsigned char>(text[8 + b])) << (8 * b);
    headerStart = 12;
  } else {
    throw inputError(path, 0, "unsupported .npy format version " + std::to_string(major));
  }
  if (headerLen > text.size() - headerStart) throw inputError(path, 0, "truncated .npy header");
  NpyHeader h = parseNpyHeader(path, std::string_view(text).substr(headerStart, headerLen));
  size_t item = 0;
  if (h.descr == "<f4") item = 4;
  else if (h.descr == "<f8") item = 8;
  else if (h.descr == ">f4" || h.descr == ">f8")
    throw inputError(path, 0, "big-endian .npy data (" + h.descr + ") is not supported; save it as '<f4' or '<f8'");
  else throw inputError(path, 0, "unsupported .npy dtype " + io::quoted(h.descr) + " (expected float32 '<f4' or float64 '<f8')");
  if (h.fortran) throw inputError(path, 0, "Fortran-order .npy arrays are not supported (save with C order)");
  if (h.shape.size() != 4 || h.shape[3] != 3) {
    std::string s = "(";
    for (size_t a = 0; a < h.shape.size(); ++a) s += (a ? ", " : "") + std::to_string(h.shape[a]);
    throw inputError(path, 0, "array shape " + s + ") is not (mu, mv, mw, 3)");
  }
  Lattice L;
  for (int a = 0; a < 3; ++a) {
    if (h.shape[a] < 2 || h.shape[a] > kMaxLatticeAxisCount)
      throw inputError(path, 0, "array shape has " + std::to_string(h.shape[a]) + " control points on axis " + "uvw"[a] +
                                    " (2.." + std::to_string(kMaxLatticeAxisCount) + " supported)");
    L.counts[a] = int(h.shape[a]);
  }
  if (L.pointCount() > kMaxLatticeControlPoints) throw inputError(path, 0, "lattice too large");
  const size_t dataStart = headerStart + headerLen;
  const size_t need = L.pointCount() * 3 * item;
  if (text.size() - dataStart != need)
    throw inputError(path, 0, std::string(text.size() - dataStart < need ? "truncated .npy data" : ".npy file has trailing data") +
                                  ": shape needs " + std::to_string(need) + " bytes, the file holds " +
                                  std::to_string(text.size() - dataStart));
  if (!options.haveMeshBox)
    throw inputError(path, 0, ".npy lattices carry no box: the mesh's (normalised) bounding box is needed to read one");
  L.degree = options.npyDegree;
  for (int a = 0; a < 3; ++a) {
    if (L.degree[a] < 1 || L.degree[a] > 5) throw inputError(path, 0, "degree must be 1..5");
    if (L.counts[a] <= L.degree[a])
      throw inputError(path, 0, "axis " + std::string(1, "uvw"[a]) + " has " + std::to_string(L.counts[a]) +
                                    " control points, too few for degree " + std::to_string(L.degree[a]));
    if (!(options.meshBoxHi[a] > options.meshBoxLo[a]))
      throw inputError(path, 0, "the mesh box is empty on axis " + std::string(1, "xyz"[a]) + " (a flat mesh needs a native lattice)");
    L.knots[a] = clampedUniformKnots(L.counts[a], L.degree[a], options.meshBoxLo[a], options.meshBoxHi[a]);
  }
  L.controlPoints.resize(L.pointCount());
  const char* p = text.data() + dataStart;
  for (size_t i = 0; i < L.pointCount(); ++i)
    for (int c = 0; c < 3; ++c, p += item) {
      double v;
      if (item == 4) {
        float f;
        std::memcpy(&f, p, 4);
        v = f;
      } else {
        std::memcpy(&v, p, 8);
      }
      if (!std::isfinite(v)) throw inputError(path, 0, "control point " + std::to_string(i) + " is not finite");
      L.controlPoints[i][c] = v;
    }
  validateLattice(L, path);
  return L;
}


// ---------------------------------------------------------------------------------------------------
// Writers of the .npy and .prm forms (readers above: what they write reads back to the same lattice
// under the reader's conventions).

void writeNpy(const std::string& path, const Lattice& L) {
  validateLattice(L, path);
  // numpy format 1.0: magic, header length, a Python dict literal padded with spaces to a multiple of
  // 64 bytes (with the magic and length) and ended by a newline; then the array, little-endian float64.
  std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (" + std::to_string(L.counts[0]) + ", " +
                     std::to_string(L.counts[1]) + ", " + std::to_string(L.counts[2]) + ", 3), }";
  const size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string bytes = "\x93NUMPY";
  bytes += char(1), bytes += char(0);
  bytes += char(dict.size() & 0xff), bytes += char(dict.size() >> 8);
  bytes += dict;
  // The points as they lie in memory (little-endian hosts only: x86-64, arm64), written straight from the
  // lattice: a copy would double the peak of a lattice of 2^24 points (400 MB).
  static_assert(sizeof(glm::dvec3) == 3 * sizeof(double));
  writeFileAtomically(path, [&](std::ostream& os) {
    os.write(bytes.data(), std::streamsize(bytes.size()));
    os.write(reinterpret_cast<const char*>(L.controlPoints.data()), std::streamsize(L.controlPoints.size() * sizeof(glm::dvec3)));
  }, true);
}

void writePrm(const std::string& path, const Lattice& L) {
  validateLattice(L, path);
  // PyGeM's lattice is one Bernstein box: degree counts-1 on every axis, no interior knots.
  for (int a = 0; a < 3; ++a) {
    const auto& k = L.knots[a];
    bool oneBox = L.degree[a] == L.counts[a] - 1;
    for (size_t i = 0; oneBox && i < k.size(); ++i) oneBox = k[i] == (i < k.size() / 2 ? k.front() : k.back());
    if (!oneBox)
      throw inputError(path, 0, "a .prm lattice is one Bezier box (degree = counts - 1, no interior knots) on every axis; "
                                "this lattice is not: write .json");
  }
  // World box: x = origin + A s, s in [0,1]^3, with A = R diag(length) and R = Rx Ry Rz (the reader's).
  const glm::dmat3 inv = glm::inverse(L.frameLinear);
  glm::dvec3 lo, hi;
  for (int a = 0; a < 3; ++a) lo[a] = L.domainLo(a), hi[a] = L.domainHi(a);
  const glm::dvec3 origin = inv * (lo - L.frameOffset);
  glm::dmat3 A = inv;
  for (int c = 0; c < 3; ++c) A[c] *= hi[c] - lo[c];
  glm::dvec3 length;
  glm::dmat3 R = A;
  for (int c = 0; c < 3; ++c) length[c] = glm::length(A[c]), R[c] /= length[c];
  // Angles of R = Rx(x) Ry(y) Rz(z), glm's m[col][row]: R02 = sin y, R12 = -sin x cos y, R22 = cos x cos y,
  // R01 = -cos y sin z, R00 = cos y cos z.
  const double ay = std::asin(std::clamp(R[2][0], -1.0, 1.0)), ax = std::atan2(-R[2][1], R[2][2]),
               az = std::atan2(-R[1][0], R[0][0]);
  const glm::dmat3 back = rotationX(ax) * rotationY(ay) * rotationZ(az);
  double off = 0;
  for (int c = 0; c < 3; ++c) off = std::max(off, glm::length(back[c] - R[c]));
  if (!(off < 1e-9))
    throw inputError(path, 0, "the lattice's box is not a rotated rectangular box, which is all a .prm file can hold: write .json");
  const double deg = 180.0 / std::numbers::pi;
  PygemParameters P;
  P.counts = L.counts, P.origin = origin, P.length = length, P.angleDeg = glm::dvec3(ax, ay, az) * deg;
  // Displacements normalised by the box: mu = A^-1 (P - origin) - s.
  const glm::dmat3 Ainv = glm::inverse(A);
  P.mu.resize(L.pointCount());
  for (int i = 0; i < L.counts[0]; ++i)
    for (int j = 0; j < L.counts[1]; ++j)
      for (int k = 0; k < L.counts[2]; ++k) {
        const glm::dvec3 s(double(i) / (L.counts[0] - 1), double(j) / (L.counts[1] - 1), double(k) / (L.counts[2] - 1));
        P.mu[L.index(i, j, k)] = Ainv * (L.controlPoints[L.index(i, j, k)] - origin) - s;
      }
  writePrmParameters(path, P);
}

// Legacy VTK (ASCII, version 3.0): the control net as a structured grid, which ParaView and VisIt open
// as they are; x (the lattice's i) varies fastest in VTK's point order, the reverse of ours. Each point
// also carries its displacement from the identity lattice's point, to colour or glyph by.
void writeVtk(const std::string& path, const Lattice& L) {
  validateLattice(L, path);
  Lattice identity = L;
  setIdentityControlPoints(identity);
  std::string s = "# vtk DataFile Version 3.0\nsffd lattice: degree " + std::to_string(L.degree[0]) + "," +
                  std::to_string(L.degree[1]) + "," + std::to_string(L.degree[2]) + "\nASCII\nDATASET STRUCTURED_GRID\n";
  s += "DIMENSIONS " + std::to_string(L.counts[0]) + " " + std::to_string(L.counts[1]) + " " + std::to_string(L.counts[2]) + "\n";
  auto points = [&](const std::vector<glm::dvec3>& values, const std::vector<glm::dvec3>* minus) {
    for (int k = 0; k < L.counts[2]; ++k)
      for (int j = 0; j < L.counts[1]; ++j)
        for (int i = 0; i < L.counts[0]; ++i) {
          glm::dvec3 v = values[L.index(i, j, k)];
          if (minus) v -= (*minus)[L.index(i, j, k)];
          for (int c = 0; c < 3; ++c) {
            io::appendNumber(s, v[c], 0);
            s += c < 2 ? ' ' : '\n';
          }
        }
  };
  s += "POINTS " + std::to_string(L.pointCount()) + " double\n";
  points(L.controlPoints, nullptr);
  s += "POINT_DATA " + std::to_string(L.pointCount()) + "\nVECTORS displacement double\n";
  points(L.controlPoints, &identity.controlPoints);
  writeFileAtomically(path, [&](std::ostream& os) { os.write(s.data(), std::streamsize(s.size())); });
}

void writePrmParameters(const std::string& path, const PygemParameters& P) {
  latticeOfPrm(P, path);   // the same checks as reading
  auto num = [](double v) {
    std::string s;
    io::appendNumber(s, v, 0);
    return s;
  };
  static const char* xyz[3] = {"x", "y", "z"};
  std::string t = "[Box info]\n# Written by sffd: PyGeM's FFD parameters (points outside the box are left unmoved).\n";
  for (int a = 0; a < 3; ++a) t += std::string("n control points ") + xyz[a] + ": " + std::to_string(P.counts[a]) + "\n";
  for (int a = 0; a < 3; ++a) t += std::string("box length ") + xyz[a] + ": " + num(P.length[a]) + "\n";
  for (int a = 0; a < 3; ++a) t += std::string("box origin ") + xyz[a] + ": " + num(P.origin[a]) + "\n";
  for (int a = 0; a < 3; ++a) t += std::string("rotation angle ") + xyz[a] + ": " + num(P.angleDeg[a]) + "\n";
  t += "\n[Parameters weights]\n";
  for (int a = 0; a < 3; ++a) {
    t += std::string("parameter ") + xyz[a] + ":";
    bool first = true;
    for (int i = 0; i < P.counts[0]; ++i)
      for (int j = 0; j < P.counts[1]; ++j)
        for (int k = 0; k < P.counts[2]; ++k) {
          const size_t id = (size_t(i) * P.counts[1] + j) * P.counts[2] + k;
          const double mu = P.mu.empty() ? 0.0 : P.mu[id][a];
          t += (first ? " " : "    ") + std::to_string(i) + " " + std::to_string(j) + " " + std::to_string(k) + " " + num(mu) + "\n";
          first = false;
        }
  }
  writeFileAtomically(path, [&](std::ostream& os) { os << t; }, true);
}

}  // namespace sffd::latticeio
