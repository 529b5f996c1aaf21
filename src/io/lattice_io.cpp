// Lattice files: dispatch, the native JSON format (read and write) and the presets of `sffd lattice`.
// PyGeM .prm and .npy are in lattice_io_formats.cpp.
//
// JSON (docs/CLI.md "Inputs"), every field checked, errors as "file:line: what":
//   "format": "sffd-lattice", "version": 1                                   required
//   "degree": [du, dv, dw] (1..5), "counts": [cu, cv, cw] (> degree)         required
//   "box": {"min": [x, y, z], "max": [x, y, z]}  (min < max)                 required
//   "knots": {"u": [...], "v": [...], "w": [...]}                            optional; an absent or empty
//        vector is the clamped uniform one over the box; a given one has counts+degree+1 non-decreasing
//        values and its domain [knots[degree], knots[counts]] must be the box's extent on that axis
//   "control_points": [[x, y, z], ...]   counts product points, (i*cv + j)*cw + k   optional, default
//        the Greville points (identity); or "displacements": [[dx, dy, dz], ...] added to them
//   "outside": "extrapolate" | "keep"                                        optional, default extrapolate
//   "frame": {"matrix": [[a, b, c], [d, e, f], [g, h, i]], "offset": [x, y, z]}   optional, default
//        identity: lattice parameter p = matrix * x + offset (matrix given by rows) for a world point x;
//        "box" and "knots" are then in parameter space (a PyGeM lattice written as JSON keeps its frame)
//   "comment" and keys starting with "_" are ignored; any other key is an error (catches typos).
// Comments (// and /* */) are accepted.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <numbers>
#include <nlohmann/json.hpp>
#include <ostream>
#include <unordered_map>
#include <unordered_set>

#include "io/atomic_file.h"
#include <sffd/error.h>
#include "io/io_util.h"
#include "io/lattice_io_internal.h"
#include "core/job_budget.h"

namespace sffd {
namespace latticeio {

// How a memory limit given is named in messages (the tool renames it SFFD_MEMORY_LIMIT).
constexpr const char* kLimitName = "LatticeReadOptions::memoryLimit";

namespace {

using json = nlohmann::json;

// An input iterator over the text that records how far the parser has read, so that parse events can
// be given line numbers.
struct TrackingIterator {
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;
  const char* p = nullptr;
  const char** furthest = nullptr;
  reference operator*() const { return *p; }
  TrackingIterator& operator++() {
    ++p;
    if (furthest && p > *furthest) *furthest = p;
    return *this;
  }
  TrackingIterator operator++(int) {
    TrackingIterator t = *this;
    ++*this;
    return t;
  }
  bool operator==(const TrackingIterator& o) const { return p == o.p; }
  bool operator!=(const TrackingIterator& o) const { return p != o.p; }
};

// Lines of the JSON values at depth <= 2 ("/counts", "/box/min", "/control_points/17"), from parse events.
class LineMap {
 public:
  explicit LineMap(std::string_view text) : text_(text), furthest_(text.data()) {
    for (size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') newlines_.push_back(i);
  }
  const char** furthest() { return &furthest_; }

  bool event(json::parse_event_t ev, const json& parsed) {
    switch (ev) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        beginElement();
        stack_.push_back({ev == json::parse_event_t::array_start, -1, {}});
        break;
      case json::parse_event_t::key:
        if (!stack_.empty()) {
          stack_.back().key = parsed.is_string() ? parsed.get<std::string>() : std::string();
          // JSON leaves a repeated key to the reader (nlohmann keeps the last): which one was meant is unknown.
          if (!stack_.back().keys.insert(stack_.back().key).second && duplicateKey_.empty()) {
            duplicateKey_ = stack_.back().key;
            duplicateLine_ = lineOfOffset(size_t(furthest_ - text_.data()) - (text_.empty() ? 0 : 1));
          }
          record();
        }
        break;
      case json::parse_event_t::value: beginElement(); break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!stack_.empty()) stack_.pop_back();
        break;
    }
    return true;
  }

  // Line of `path`, else of its nearest recorded parent; 0 when unknown.
  size_t line(std::string path) const {
    while (true) {
      auto it = lines_.find(path);
      if (it != lines_.end()) return it->second;
      size_t slash = path.rfind('/');
      if (slash == std::string::npos || path.empty()) return 0;
      path.resize(slash);
      if (path.empty()) return 0;
    }
  }
  size_t lineOfOffset(size_t offset) const {
    return 1 + size_t(std::lower_bound(newlines_.begin(), newlines_.end(), offset) - newlines_.begin());
  }
  // The first key given twice in one object (empty when none), and its second line.
  const std::string& duplicateKey() const { return duplicateKey_; }
  size_t duplicateLine() const { return duplicateLine_; }

 private:
  struct Frame {
    bool array;
    long index;
    std::string key;
    std::unordered_set<std::string> keys = {};   // an object's keys so far
  };
  void beginElement() {
    if (!stack_.empty() && stack_.back().array) ++stack_.back().index;
    record();
  }
  void record() {
    if (stack_.size() > 2) return;
    std::string path;
    for (const Frame& f : stack_) path += "/" + (f.array ? std::to_string(f.index) : f.key);
    if (path.empty()) return;
    // The element's line: the last non-blank character read (the parser reads at most one past a token).
    const char* q = furthest_;
    while (q > text_.data() && io::isSpace(q[-1])) --q;
    size_t off = q > text_.data() ? size_t(q - 1 - text_.data()) : 0;
    lines_.emplace(path, lineOfOffset(off));
  }
  std::string_view text_;
  const char* furthest_;
  std::vector<size_t> newlines_;
  std::vector<Frame> stack_;
  std::unordered_map<std::string, size_t> lines_;
  std::string duplicateKey_;
  size_t duplicateLine_ = 0;
};

std::string stripNlohmannPrefix(const std::string& what) {
  // "[json.exception.parse_error.101] parse error at line 3, column 5: syntax error while ..." -> "syntax error while ..."
  size_t c = what.find("column ");
  if (c != std::string::npos) {
    size_t colon = what.find(": ", c);
    if (colon != std::string::npos) return what.substr(colon + 2);
  }
  size_t b = what.find("] ");
  return b == std::string::npos ? what : what.substr(b + 2);
}

}  // namespace

Lattice readJson(const std::string& path, const std::string& text, uint64_t memoryLimit) {
  LineMap lines(text);
  json j;
  try {
    TrackingIterator first{text.data(), lines.furthest()}, last{text.data() + text.size(), nullptr};
    j = json::parse(
        first, last, [&](int, json::parse_event_t ev, json& parsed) { return lines.event(ev, parsed); }, true, true);
  } catch (const json::parse_error& e) {
    size_t line = lines.lineOfOffset(e.byte > 0 ? e.byte - 1 : 0);
    throw inputError(path, line, "JSON syntax error: " + stripNlohmannPrefix(e.what()));
  } catch (const json::exception& e) {   // e.g. out_of_range.406: a number too large for a double
    size_t line = lines.lineOfOffset(size_t(*lines.furthest() - text.data()) - (text.empty() ? 0 : 1));
    throw inputError(path, line, "JSON error: " + stripNlohmannPrefix(e.what()));
  }
  if (!lines.duplicateKey().empty())
    throw inputError(path, lines.duplicateLine(), "the key " + io::quoted(lines.duplicateKey()) + " is given twice in one object");
  auto fail = [&](const std::string& at, const std::string& what) { return inputError(path, lines.line(at), what); };
  if (!j.is_object()) throw inputError(path, 1, "expected a JSON object {\"format\": \"sffd-lattice\", ...}");

  static const char* allowed[] = {"format", "version", "degree", "counts", "box", "knots", "control_points",
                                  "displacements", "outside", "frame", "comment"};
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    if (!k.empty() && k[0] == '_') continue;
    if (std::find_if(std::begin(allowed), std::end(allowed), [&](const char* a) { return k == a; }) == std::end(allowed))
      throw fail("/" + k, "unknown field \"" + k + "\"");
  }
  auto need = [&](const char* key) -> const json& {
    if (!j.contains(key)) throw inputError(path, 0, std::string("missing field \"") + key + "\"");
    return j[key];
  };
  auto intTriple = [&](const json& v, const std::string& at, const char* what) {
    if (!v.is_array() || v.size() != 3) throw fail(at, std::string(what) + " must be an array of 3 integers");
    std::array<int, 3> r{};
    for (int a = 0; a < 3; ++a) {
      if (!v[a].is_number_integer()) throw fail(at, std::string(what) + " must be an array of 3 integers");
      long long x = v[a].get<long long>();
      if (x < -1000000 || x > 1000000) throw fail(at, std::string(what) + " value " + std::to_string(x) + " is out of range");
      r[a] = int(x);
    }
    return r;
  };
  auto vec3 = [&](const json& v, const std::string& at, const std::string& what) {
    if (!v.is_array() || v.size() != 3) throw fail(at, what + " must be an array of 3 numbers");
    glm::dvec3 r;
    for (int a = 0; a < 3; ++a) {
      if (!v[a].is_number()) throw fail(at, what + " must be an array of 3 numbers");
      r[a] = v[a].get<double>();
      if (!std::isfinite(r[a])) throw fail(at, what + " has a non-finite value");
    }
    return r;
  };

  const json& fmt = need("format");
  if (!fmt.is_string() || fmt.get<std::string>() != "sffd-lattice") throw fail("/format", "format must be \"sffd-lattice\"");
  const json& ver = need("version");
  if (!ver.is_number_integer() || ver.get<long long>() != 1) throw fail("/version", "unsupported version (this reader knows version 1)");

  Lattice L;
  L.degree = intTriple(need("degree"), "/degree", "degree");
  L.counts = intTriple(need("counts"), "/counts", "counts");
  static const char* axisName = "uvw";
  for (int a = 0; a < 3; ++a) {
    if (L.degree[a] < 1 || L.degree[a] > 5) throw fail("/degree", "degree values must be 1..5");
    if (L.counts[a] <= L.degree[a]) throw fail("/counts", "counts must exceed the degree on every axis (counts >= degree + 1)");
    if (L.counts[a] > kMaxLatticeAxisCount)
      throw fail("/counts", "counts above " + std::to_string(kMaxLatticeAxisCount) + " per axis are not supported");
  }
  if (L.pointCount() > kMaxLatticeControlPoints)
    throw fail("/counts", "lattice of " + std::to_string(L.pointCount()) + " control points is too large (at most " +
                              std::to_string(kMaxLatticeControlPoints) + ")");

  const json& box = need("box");
  if (!box.is_object() || !box.contains("min") || !box.contains("max"))
    throw fail("/box", "box must be {\"min\": [x, y, z], \"max\": [x, y, z]}");
  glm::dvec3 lo = vec3(box["min"], "/box/min", "box.min"), hi = vec3(box["max"], "/box/max", "box.max");
  for (int a = 0; a < 3; ++a)
    if (!(hi[a] > lo[a])) throw fail("/box", "box.max must exceed box.min on every axis (zero-size or inverted box)");

  if (j.contains("frame")) {
    const json& f = j["frame"];
    if (!f.is_object() || !f.contains("matrix")) throw fail("/frame", "frame must be {\"matrix\": [[3], [3], [3]], \"offset\": [3]}");
    const json& m = f["matrix"];
    if (!m.is_array() || m.size() != 3) throw fail("/frame/matrix", "frame.matrix must be 3 rows of 3 numbers");
    for (int r = 0; r < 3; ++r) {
      glm::dvec3 row = vec3(m[r], "/frame/matrix", "frame.matrix row");
      for (int c = 0; c < 3; ++c) L.frameLinear[c][r] = row[c];
    }
    if (f.contains("offset")) L.frameOffset = vec3(f["offset"], "/frame/offset", "frame.offset");
    double det = glm::determinant(L.frameLinear);
    if (!std::isfinite(det) || std::abs(det) < 1e-300) throw fail("/frame", "frame.matrix is singular");
  }

  if (j.contains("outside")) {
    const json& o = j["outside"];
    std::string s = o.is_string() ? o.get<std::string>() : "";
    if (s == "extrapolate") L.outside = OutsideMode::Extrapolate;
    else if (s == "keep") L.outside = OutsideMode::Keep;
    else throw fail("/outside", "outside must be \"extrapolate\" or \"keep\"");
  }

  const json* knots = j.contains("knots") ? &j["knots"] : nullptr;
  if (knots && !knots->is_object()) throw fail("/knots", "knots must be {\"u\": [...], \"v\": [...], \"w\": [...]}");
  for (int a = 0; a < 3; ++a) {
    std::string key(1, axisName[a]);
    const json* kv = knots && knots->contains(key) ? &(*knots)[key] : nullptr;
    if (kv && !kv->is_array()) throw fail("/knots/" + key, "knots." + key + " must be an array of numbers");
    if (!kv || kv->empty()) {
      L.knots[a] = clampedUniformKnots(L.counts[a], L.degree[a], lo[a], hi[a]);
      continue;
    }
    size_t want = size_t(L.counts[a] + L.degree[a] + 1);
    if (kv->size() != want)
      throw fail("/knots/" + key, "knots." + key + " has " + std::to_string(kv->size()) + " values; counts+degree+1 = " +
                                      std::to_string(want) + " needed");
    for (const json& x : *kv) {
      if (!x.is_number()) throw fail("/knots/" + key, "knots." + key + " must hold numbers");
      double d = x.get<double>();
      if (!std::isfinite(d)) throw fail("/knots/" + key, "knots." + key + " has a non-finite value");
      if (!L.knots[a].empty() && d < L.knots[a].back()) throw fail("/knots/" + key, "knots." + key + " must be non-decreasing");
      L.knots[a].push_back(d);
    }
    double dlo = L.knots[a][size_t(L.degree[a])], dhi = L.knots[a][size_t(L.counts[a])];
    double tol = 1e-9 * (hi[a] - lo[a]);
    if (!(dhi > dlo)) throw fail("/knots/" + key, "knots." + key + " has an empty domain");
    if (std::abs(dlo - lo[a]) > tol || std::abs(dhi - hi[a]) > tol)
      throw fail("/knots/" + key, "knots." + key + " spans [" + io::formatNumber(dlo) + ", " + io::formatNumber(dhi) +
                                      "] (knots[degree], knots[counts]) but the box spans [" + io::formatNumber(lo[a]) + ", " +
                                      io::formatNumber(hi[a]) + "]");
  }

  if (j.contains("control_points") && j.contains("displacements"))
    throw fail("/displacements", "give either control_points or displacements, not both");
  const char* pointsKey = j.contains("control_points") ? "control_points" : j.contains("displacements") ? "displacements" : nullptr;
  // A few bytes of counts can ask for gigabytes: refused before the points are made.
  if (std::string big = latticeTooLarge(L, memoryLimit, kLimitName); !big.empty()) throw fail("/counts", big);
  setIdentityControlPoints(L);
  if (pointsKey) {
    const json& pts = j[pointsKey];
    std::string at = std::string("/") + pointsKey;
    if (!pts.is_array()) throw fail(at, std::string(pointsKey) + " must be an array of [x, y, z] points");
    if (pts.size() != L.pointCount())
      throw fail(at, std::string(pointsKey) + " has " + std::to_string(pts.size()) + " points; counts " +
                         std::to_string(L.counts[0]) + "x" + std::to_string(L.counts[1]) + "x" + std::to_string(L.counts[2]) +
                         " need " + std::to_string(L.pointCount()));
    bool displace = std::strcmp(pointsKey, "displacements") == 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      glm::dvec3 v = vec3(pts[i], at + "/" + std::to_string(i), std::string(pointsKey) + "[" + std::to_string(i) + "]");
      L.controlPoints[i] = displace ? L.controlPoints[i] + v : v;
    }
  }
  validateLattice(L, path);
  return L;
}

}  // namespace latticeio

Lattice readLattice(const std::string& path, const LatticeReadOptions& options) {
  std::string ext = io::lowerExtension(path);
  if (path.empty()) throw Error(ErrorKind::Input, "the lattice's file name is empty");
  try {
    if (ext != ".json" && ext != ".prm" && ext != ".npy")
      throw inputError(path, 0,
                       "unknown lattice format " + (ext.empty() ? std::string("(no extension)") : io::quoted(ext)) +
                           "; expected .json, .prm or .npy");
    return latticeio::readLatticeBytes(path, io::readWholeFile(path), options);
  } catch (const Error& e) {
    throw Error(e.kind(), io::oneLine(e.what()));   // a file name with a newline still makes one line
  }
}

PygemParameters readPygemParameters(const std::string& path) {
  try {
    std::string text = io::readWholeFile(path);
    if (text.empty()) throw inputError(path, 0, "empty file");
    io::checkTextEncoding(path, text, false);
    return latticeio::parsePrm(path, text);
  } catch (const Error& e) {
    throw Error(e.kind(), io::oneLine(e.what()));
  }
}

void writePygemParameters(const std::string& path, const PygemParameters& parameters) {
  latticeio::writePrmParameters(path, parameters);
}

Lattice pygemLattice(const PygemParameters& parameters) { return latticeio::latticeOfPrm(parameters, "PyGeM parameters"); }

namespace latticeio {

Lattice readLatticeBytes(const std::string& path, std::string text, const LatticeReadOptions& options) {
  try {
    std::string ext = io::lowerExtension(path);
    if (text.empty()) throw inputError(path, 0, "empty file");
    if (ext != ".npy") io::checkTextEncoding(path, text, false);   // no UTF-16, no binary; a UTF-8 BOM skipped
    if (ext == ".json") return readJson(path, text, options.memoryLimit);
    if (ext == ".prm" || ext == ".npy") {
      Lattice L = ext == ".prm" ? readPrm(path, text) : readNpy(path, text, options);
      // The points are in the file; the box form, up to (n+1)^3 times more, is not.
      if (std::string big = latticeTooLarge(L, options.memoryLimit, kLimitName); !big.empty()) throw inputError(path, 0, big);
      return L;
    }
    throw inputError(path, 0, "unknown lattice format " + io::quoted(ext));
  } catch (const Error& e) {
    throw Error(e.kind(), io::oneLine(e.what()));   // a message is one line, whatever the file held
  }
}

}  // namespace latticeio

// ---------------------------------------------------------------------------------------------------
// Writing: numbers in their shortest form that reads back to the same double (at most 17 significant
// digits), so a written lattice reads back bit for bit. "knots" is written only when some knot vector is
// not the clamped uniform one over the box (the others then as []), "frame" only when it is not the
// identity; "outside" and "control_points" always.

void writeLattice(const std::string& path, const Lattice& lattice) {
  const std::string ext = io::lowerExtension(path);
  if (ext == ".json") return writeLatticeJson(path, lattice);
  if (ext == ".npy") return latticeio::writeNpy(path, lattice);
  if (ext == ".prm") return latticeio::writePrm(path, lattice);
  if (ext == ".vtk") return latticeio::writeVtk(path, lattice);
  throw inputError(path, 0, "cannot write lattice format " + (ext.empty() ? std::string("(no extension)") : io::quoted(ext)) +
                                "; expected .json, .npy, .prm or .vtk");
}

void writeLatticeJson(const std::string& path, const Lattice& L) {
  validateLattice(L, path);
  glm::dvec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = L.domainLo(a);
    hi[a] = L.domainHi(a);
  }
  auto num = [](std::string& s, double v) { io::appendNumber(s, v, 0); };
  auto vec = [&](std::string& s, const glm::dvec3& v) {
    s += '[';
    num(s, v.x);
    s += ", ";
    num(s, v.y);
    s += ", ";
    num(s, v.z);
    s += ']';
  };
  auto triple = [](const std::array<int, 3>& t) {
    return "[" + std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) + "]";
  };
  std::string s = "{\n  \"format\": \"sffd-lattice\",\n  \"version\": 1,\n";
  s += "  \"degree\": " + triple(L.degree) + ",\n";
  s += "  \"counts\": " + triple(L.counts) + ",\n";
  s += "  \"box\": {\"min\": ";
  vec(s, lo);
  s += ", \"max\": ";
  vec(s, hi);
  s += "},\n";
  bool uniform[3];
  bool anyKnots = false;
  for (int a = 0; a < 3; ++a) {
    uniform[a] = L.knots[a] == clampedUniformKnots(L.counts[a], L.degree[a], lo[a], hi[a]);
    anyKnots = anyKnots || !uniform[a];
  }
  if (anyKnots) {
    s += "  \"knots\": {";
    for (int a = 0; a < 3; ++a) {
      s += std::string(a ? ", " : "") + "\"" + "uvw"[a] + "\": [";
      if (!uniform[a])
        for (size_t i = 0; i < L.knots[a].size(); ++i) {
          if (i) s += ", ";
          num(s, L.knots[a][i]);
        }
      s += "]";
    }
    s += "},\n";
  }
  if (L.frameLinear != glm::dmat3(1.0) || L.frameOffset != glm::dvec3(0.0)) {
    s += "  \"frame\": {\"matrix\": [";
    for (int r = 0; r < 3; ++r) {
      if (r) s += ", ";
      vec(s, glm::dvec3(L.frameLinear[0][r], L.frameLinear[1][r], L.frameLinear[2][r]));
    }
    s += "], \"offset\": ";
    vec(s, L.frameOffset);
    s += "},\n";
  }
  s += std::string("  \"outside\": \"") + (L.outside == OutsideMode::Keep ? "keep" : "extrapolate") + "\",\n";
  s += "  \"control_points\": [";
  // The control points written a block at a time: a lattice of 2^24 points is a 1 GB text.
  writeFileAtomically(path, [&](std::ostream& os) {
    for (size_t i = 0; i < L.controlPoints.size(); ++i) {
      s += i ? ",\n    " : "\n    ";
      vec(s, L.controlPoints[i]);
      if (s.size() >= (1u << 20)) os.write(s.data(), std::streamsize(s.size())), s.clear();
    }
    s += "\n  ]\n}\n";
    os.write(s.data(), std::streamsize(s.size()));
  });
}

// ---------------------------------------------------------------------------------------------------
// Presets. All work in the lattice box's own axes: with the box's world centre c and half-edge vectors
// E_a (the parameter-space domain mapped back through the frame; for a native lattice E_a is the box's
// half extent along world axis a), a control point x = c + sum_a s_a E_a has local coordinates
// t_a = s_a |E_a| (model units, zero at the centre) on unit axes d_a = E_a / |E_a|. A preset maps t to t'
// and moves x by sum_a (t'_a - t_a) d_a. h_a = |E_a| are the half extents; L is the longest axis (the
// first of equal ones, equal to rounding), S the second longest, and s = t_L / h_L in [-1, 1] runs along
// L. Amount 1 is the intended default of every preset.
//   twist: rotate the cross-section (the two axes other than L) about L by the angle a * 90deg * s / 2,
//          i.e. a * 90deg in all from one end of the box to the other, the middle fixed.
//   bend:  t'_S = t_S + a * 0.5 * h_S * s^2: a parabola along L bending toward +S, the ends moving by
//          a * h_S / 2.
//   taper: scale the cross-section by 1 - (a/2) * (s + 1)/2: 1 at the low end of L, 1 - a/2 at the high end.
//   bulge: scale the cross-section by 1 + (a/2) * (1 - s^2): 1 + a/2 in the middle, 1 at both ends.
//   noise: move every control point by a * 0.1 * (box edge length) * r_a along each axis a, r_a uniform in
//          [-1, 1) from a fixed-seed SplitMix64 sequence in control point order: the same lattice always
//          gets the same noise.

void applyLatticePreset(Lattice& lattice, const std::string& name, double amount) {
  static const char* names[] = {"twist", "bend", "taper", "bulge", "noise"};
  if (std::find_if(std::begin(names), std::end(names), [&](const char* n) { return name == n; }) == std::end(names))
    throw inputError("", 0, "unknown lattice preset " + io::quoted(name) + "; expected twist, bend, taper, bulge or noise");
  if (!std::isfinite(amount)) throw inputError("", 0, "preset amount must be a finite number");
  validateLattice(lattice, "applyLatticePreset");   // a default-constructed Lattice has no knots to read
  glm::dmat3 inv = glm::inverse(lattice.frameLinear);
  glm::dvec3 pc, ph;   // parameter-space centre and half extents
  for (int a = 0; a < 3; ++a) {
    pc[a] = 0.5 * (lattice.domainLo(a) + lattice.domainHi(a));
    ph[a] = 0.5 * (lattice.domainHi(a) - lattice.domainLo(a));
  }
  glm::dvec3 c = inv * (pc - lattice.frameOffset);
  glm::dvec3 d[3];
  double h[3];
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 e(0.0);
    e[a] = ph[a];
    glm::dvec3 E = inv * e;
    h[a] = std::hypot(E.x, E.y, E.z);   // glm::length's square leaves double's range for a box 1e-160 or 1e160 across
    if (!(h[a] > 0) || !std::isfinite(h[a]))
      throw inputError("applyLatticePreset", 0, "the lattice's box has an edge of no length or beyond double's range in world units");
    d[a] = E / h[a];
  }
  // Longer by more than rounding: the box fitted to a cube differs from axis to axis by the rounding of its
  // corners, which grows with the distance from the origin, and the twist's axis turned with it.
  const double rounding = 64 * std::numeric_limits<double>::epsilon() *
                          (std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z)}) + std::max({h[0], h[1], h[2]}));
  auto longer = [&](int a, int b) { return h[a] - h[b] > rounding; };
  int Lx = 0;
  for (int a = 1; a < 3; ++a)
    if (longer(a, Lx)) Lx = a;
  int S = -1;
  for (int a = 0; a < 3; ++a)
    if (a != Lx && (S < 0 || longer(a, S))) S = a;
  int B = 3 - Lx - S;   // the remaining axis
  int P = std::min(S, B), Q = std::max(S, B);   // cross-section axes in x, y, z order

  uint64_t state = 0x5FFD5EED2024ull;
  auto next = [&]() {   // SplitMix64
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return double(z >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0;   // [-1, 1)
  };

  for (glm::dvec3& x : lattice.controlPoints) {
    // local coordinates: solve x - c = sum_a t_a d_a (the d_a need not be orthogonal)
    glm::dmat3 D(d[0], d[1], d[2]);
    glm::dvec3 t = glm::inverse(D) * (x - c);
    glm::dvec3 u = t;
    double s = t[Lx] / h[Lx];
    if (name == "twist") {
      double ang = amount * (std::numbers::pi / 2) * s / 2;
      double cs = std::cos(ang), sn = std::sin(ang);
      u[P] = cs * t[P] - sn * t[Q];
      u[Q] = sn * t[P] + cs * t[Q];
    } else if (name == "bend") {
      u[S] = t[S] + amount * 0.5 * h[S] * s * s;
    } else if (name == "taper") {
      double f = 1 - 0.5 * amount * (s + 1) / 2;
      u[P] = f * t[P];
      u[Q] = f * t[Q];
    } else if (name == "bulge") {
      double f = 1 + 0.5 * amount * (1 - s * s);
      u[P] = f * t[P];
      u[Q] = f * t[Q];
    } else {   // noise
      for (int a = 0; a < 3; ++a) u[a] = t[a] + amount * 0.1 * (2 * h[a]) * next();
    }
    x += (u[0] - t[0]) * d[0] + (u[1] - t[1]) * d[1] + (u[2] - t[2]) * d[2];
  }
}

}  // namespace sffd
