// Mesh files: dispatch by extension, the writers (.obj .ply .off .stl), normals and welding.
// The readers live in mesh_io_obj.cpp (OBJ), mesh_io_formats.cpp (OFF, PLY, STL), mesh_io_om.cpp
// (OpenMesh .om) and mesh_io_bpt.cpp (Bezier patches).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <ostream>
#include <unordered_map>

#include "io/atomic_file.h"
#include <sffd/error.h>
#include "io/io_util.h"
#include "model/mesh.h"
#include "io/mesh_io_internal.h"

namespace sffd {

Mesh readMesh(const std::string& path, const MeshReadOptions& options) {
  std::string ext = io::lowerExtension(path);
  static const char* known[] = {".obj", ".off", ".ply", ".stl", ".om", ".bpt"};
  bool ok = false;
  for (const char* k : known) ok = ok || ext == k;
  try {
    if (!ok)
      throw inputError(path, 0,
                       "unknown mesh format " + (ext.empty() ? std::string("(no extension)") : io::quoted(ext)) +
                           "; expected .obj, .off, .ply, .stl, .om or .bpt");
    return meshio::readMeshBytes(path, io::readWholeFile(path), options);
  } catch (const Error& e) {
    throw Error(e.kind(), io::oneLine(e.what()));   // a file name with a newline still makes one line
  }
}

namespace meshio {

namespace {
Mesh dispatch(const std::string& path, std::string text, const MeshReadOptions& options) {
  std::string ext = io::lowerExtension(path);
  if (text.empty()) throw inputError(path, 0, "empty file");
  // Text formats: no UTF-16, no binary data, a UTF-8 byte-order mark skipped. PLY has binary
  // variants (its header is checked by the PLY reader); STL and .om are checked by theirs.
  if (ext == ".obj" || ext == ".off" || ext == ".bpt" || ext == ".ply") io::checkTextEncoding(path, text, ext == ".ply");
  if (ext == ".obj") return readObj(path, text);
  if (ext == ".off") return readOff(path, text);
  if (ext == ".ply") return readPly(path, text);
  if (ext == ".stl") return readStl(path, text);
  if (ext == ".om") return readOm(path, text);
  if (ext == ".bpt") return readBpt(path, text, options);
  throw inputError(path, 0, "unknown mesh format " + io::quoted(ext));
}
}  // namespace

Mesh readMeshBytes(const std::string& path, std::string text, const MeshReadOptions& options) {
  try {
    return dispatch(path, std::move(text), options);
  } catch (const Error& e) {
    throw Error(e.kind(), io::oneLine(e.what()));   // a message is one line, whatever the file held
  }
}

}  // namespace meshio

// ---------------------------------------------------------------------------------------------------
// Normals and welding

namespace {

// Angle-weighted normal sums (unnormalised) per vertex.
std::vector<glm::dvec3> angleWeightedSums(const Mesh& mesh) {
  std::vector<glm::dvec3> sum(mesh.positions.size(), glm::dvec3(0.0));
  const size_t n = mesh.positions.size();
  for (const auto& t : mesh.triangles) {
    if (t[0] >= n || t[1] >= n || t[2] >= n) throw Error(ErrorKind::Internal, "computeVertexNormals: triangle index out of range");
    const glm::dvec3 p[3] = {mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]};
    glm::dvec3 fn = glm::cross(p[1] - p[0], p[2] - p[0]);
    double len = glm::length(fn);
    if (!(len > 0) || !std::isfinite(len)) continue;
    fn /= len;
    for (int c = 0; c < 3; ++c) {
      glm::dvec3 e1 = p[(c + 1) % 3] - p[c], e2 = p[(c + 2) % 3] - p[c];
      double angle = std::atan2(glm::length(glm::cross(e1, e2)), glm::dot(e1, e2));
      sum[t[c]] += angle * fn;
    }
  }
  return sum;
}

glm::dvec3 unitOrZ(const glm::dvec3& v) {
  double len = glm::length(v);
  if (len > 0 && std::isfinite(len)) return v / len;
  return glm::dvec3(0, 0, 1);
}

struct PositionKey {
  uint64_t x, y, z;
  bool operator==(const PositionKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PositionKeyHash {
  size_t operator()(const PositionKey& k) const {
    uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
    h ^= k.y + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= k.z + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
    return size_t(h ^ (h >> 31));
  }
};
PositionKey keyOf(const glm::dvec3& p) {
  PositionKey k;
  // + 0.0 turns -0.0 into +0.0, so that equal values give equal keys.
  double x = p.x + 0.0, y = p.y + 0.0, z = p.z + 0.0;
  std::memcpy(&k.x, &x, 8);
  std::memcpy(&k.y, &y, 8);
  std::memcpy(&k.z, &z, 8);
  return k;
}

// Index of each vertex's distinct position (first appearance order) and the number of distinct positions.
std::vector<uint32_t> distinctPositions(const std::vector<glm::dvec3>& positions, uint32_t& count) {
  std::unordered_map<PositionKey, uint32_t, PositionKeyHash> ids;
  ids.reserve(positions.size());
  std::vector<uint32_t> id(positions.size());
  for (size_t v = 0; v < positions.size(); ++v) id[v] = ids.emplace(keyOf(positions[v]), uint32_t(ids.size())).first->second;
  count = uint32_t(ids.size());
  return id;
}

}  // namespace

void computeVertexNormals(Mesh& mesh) {
  std::vector<glm::dvec3> sum = angleWeightedSums(mesh);
  mesh.normals.resize(mesh.positions.size());
  for (size_t v = 0; v < sum.size(); ++v) mesh.normals[v] = unitOrZ(sum[v]);
}

void weldPositions(Mesh& mesh) {
  uint32_t count = 0;
  mesh.weldId = distinctPositions(mesh.positions, count);
}

namespace meshio {

void finishMesh(Mesh& mesh, const std::vector<uint8_t>& fromFile, const std::string& path) {
  const size_t n = mesh.positions.size();
  if (n > kMaxVertices) throw inputError(path, 0, "too many vertices");
  if (mesh.triangles.empty()) throw inputError(path, 0, "no triangles");
  for (const auto& t : mesh.triangles)
    for (uint32_t i : t)
      if (i >= n) throw inputError(path, 0, "vertex index " + std::to_string(i) + " out of range");
  for (const auto& p : mesh.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) throw inputError(path, 0, "non-finite vertex coordinate");
  mesh.normals.resize(n, glm::dvec3(0.0));
  bool anyFromFile = false, anyComputed = false;
  std::vector<uint8_t> compute(n, 1);
  for (size_t v = 0; v < n; ++v) {
    if (v < fromFile.size() && fromFile[v]) {
      const glm::dvec3 m = mesh.normals[v];
      const double big = std::max({std::abs(m.x), std::abs(m.y), std::abs(m.z)});
      if (std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.z) && big > 0) {   // (max() passes a NaN over)
        // A normal already of unit length is kept bit for bit (so that files written by writeMesh read
        // back exactly); others are scaled by their largest component first, so that tiny (denormal) and
        // huge ones normalise without underflow or overflow.
        double len = glm::length(m);
        if (!(std::abs(len - 1.0) <= 1e-15)) {
          glm::dvec3 q = m / big;
          mesh.normals[v] = q / glm::length(q);
        }
        compute[v] = 0;
        anyFromFile = true;
        continue;
      }
    }
    anyComputed = true;
  }
  if (anyComputed) {
    std::vector<glm::dvec3> sum = angleWeightedSums(mesh);
    for (size_t v = 0; v < n; ++v)
      if (compute[v]) mesh.normals[v] = unitOrZ(sum[v]);
  }
  mesh.normalsFromFile = anyFromFile;
  weldPositions(mesh);
}

}  // namespace meshio

// ---------------------------------------------------------------------------------------------------
// Writers

namespace {

// Accumulates text and hands it to the stream in pieces (large meshes never sit in memory twice).
class ChunkedWriter {
 public:
  explicit ChunkedWriter(std::ostream& os) : os_(os) { buf_.reserve(kChunk + 1024); }
  ~ChunkedWriter() = default;
  std::string& buf() { return buf_; }
  void maybeFlush() {
    if (buf_.size() >= kChunk) flush();
  }
  void flush() {
    os_.write(buf_.data(), std::streamsize(buf_.size()));
    buf_.clear();
  }

 private:
  static constexpr size_t kChunk = 1 << 20;
  std::ostream& os_;
  std::string buf_;
};

void appendVec(std::string& s, const glm::dvec3& v, int digits) {
  io::appendNumber(s, v.x, digits);
  s += ' ';
  io::appendNumber(s, v.y, digits);
  s += ' ';
  io::appendNumber(s, v.z, digits);
}

void checkWritable(const std::string& path, const Mesh& mesh, bool& withNormals) {
  const size_t n = mesh.positions.size();
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    throw Error(ErrorKind::Internal, path + ": mesh has " + std::to_string(mesh.normals.size()) + " normals for " +
                                         std::to_string(n) + " vertices");
  withNormals = !mesh.normals.empty();
  for (const auto& t : mesh.triangles)
    for (uint32_t i : t)
      if (i >= n) throw Error(ErrorKind::Internal, path + ": mesh triangle index out of range");
  // A lattice that sends points beyond the floating-point range gives inf or NaN: refuse to write a
  // file of them, and say where (the lattice is the input at fault, so this is an input error).
  auto finite = [](const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  for (size_t v = 0; v < n; ++v)
    if (!finite(mesh.positions[v]) || (withNormals && !finite(mesh.normals[v])))
      throw Error(ErrorKind::Input, path + ": not written: vertex " + std::to_string(v) + " of the result has a " +
                                        (finite(mesh.positions[v]) ? "non-finite normal" : "non-finite position") +
                                        " (the lattice moves it beyond the floating-point range of the computation)");
}

void writeObj(std::ostream& os, const Mesh& mesh, int digits, bool withNormals) {
  // Positions are written once per distinct value (so a welded mesh stays welded for every OBJ reader),
  // normals once per vertex; a face corner is "position//normal" = "p//v".
  uint32_t count = 0;
  std::vector<uint32_t> pid = distinctPositions(mesh.positions, count);
  ChunkedWriter w(os);
  std::string& s = w.buf();
  s += "# sffd mesh: " + std::to_string(count) + " positions, " + std::to_string(mesh.positions.size()) + " vertices, " +
       std::to_string(mesh.triangles.size()) + " triangles\n";
  uint32_t next = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    if (pid[v] != next) continue;   // written already
    ++next;
    s += "v ";
    appendVec(s, mesh.positions[v], digits);
    s += '\n';
    w.maybeFlush();
  }
  if (withNormals)
    for (const auto& nrm : mesh.normals) {
      s += "vn ";
      appendVec(s, nrm, digits);
      s += '\n';
      w.maybeFlush();
    }
  for (const auto& t : mesh.triangles) {
    s += 'f';
    for (uint32_t i : t) {
      s += ' ';
      s += std::to_string(pid[i] + 1);
      if (withNormals) {
        s += "//";
        s += std::to_string(i + 1);
      }
    }
    s += '\n';
    w.maybeFlush();
  }
  w.flush();
}

void writePly(std::ostream& os, const Mesh& mesh, int digits, bool withNormals) {
  const char* type = digits > 9 ? "double" : "float";
  ChunkedWriter w(os);
  std::string& s = w.buf();
  s += "ply\nformat ascii 1.0\ncomment written by sffd\n";
  s += "element vertex " + std::to_string(mesh.positions.size()) + "\n";
  for (const char* c : {"x", "y", "z"}) s += std::string("property ") + type + " " + c + "\n";
  if (withNormals)
    for (const char* c : {"nx", "ny", "nz"}) s += std::string("property ") + type + " " + c + "\n";
  s += "element face " + std::to_string(mesh.triangles.size()) + "\n";
  s += "property list uchar int vertex_indices\nend_header\n";
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    appendVec(s, mesh.positions[v], digits);
    if (withNormals) {
      s += ' ';
      appendVec(s, mesh.normals[v], digits);
    }
    s += '\n';
    w.maybeFlush();
  }
  for (const auto& t : mesh.triangles) {
    s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
    w.maybeFlush();
  }
  w.flush();
}

void writeOff(std::ostream& os, const Mesh& mesh, int digits) {
  // OFF holds positions only: one per distinct position, so a welded mesh stays welded.
  uint32_t count = 0;
  std::vector<uint32_t> pid = distinctPositions(mesh.positions, count);
  ChunkedWriter w(os);
  std::string& s = w.buf();
  s += "OFF\n" + std::to_string(count) + " " + std::to_string(mesh.triangles.size()) + " 0\n";
  uint32_t next = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    if (pid[v] != next) continue;
    ++next;
    appendVec(s, mesh.positions[v], digits);
    s += '\n';
    w.maybeFlush();
  }
  for (const auto& t : mesh.triangles) {
    s += "3 " + std::to_string(pid[t[0]]) + " " + std::to_string(pid[t[1]]) + " " + std::to_string(pid[t[2]]) + "\n";
    w.maybeFlush();
  }
  w.flush();
}

void writeStl(std::ostream& os, const Mesh& mesh, int digits, bool withNormals) {
  // ASCII STL (so coordinates keep `digits` digits); the facet normal is the geometric one, or the mean
  // vertex normal for a degenerate triangle.
  ChunkedWriter w(os);
  std::string& s = w.buf();
  s += "solid sffd\n";
  for (const auto& t : mesh.triangles) {
    const glm::dvec3& a = mesh.positions[t[0]];
    const glm::dvec3& b = mesh.positions[t[1]];
    const glm::dvec3& c = mesh.positions[t[2]];
    glm::dvec3 fn = glm::cross(b - a, c - a);
    double len = glm::length(fn);
    if (len > 0 && std::isfinite(len)) fn /= len;
    else if (withNormals) {
      fn = mesh.normals[t[0]] + mesh.normals[t[1]] + mesh.normals[t[2]];
      len = glm::length(fn);
      fn = (len > 0 && std::isfinite(len)) ? fn / len : glm::dvec3(0.0);
    } else {
      fn = glm::dvec3(0.0);
    }
    s += "  facet normal ";
    appendVec(s, fn, digits);
    s += "\n    outer loop\n";
    for (uint32_t i : t) {
      s += "      vertex ";
      appendVec(s, mesh.positions[i], digits);
      s += '\n';
    }
    s += "    endloop\n  endfacet\n";
    w.maybeFlush();
  }
  s += "endsolid sffd\n";
  w.flush();
}

}  // namespace

void writeMesh(const std::string& path, const Mesh& mesh, int significantDigits) {
  std::string ext = io::lowerExtension(path);
  if (ext != ".obj" && ext != ".ply" && ext != ".off" && ext != ".stl")
    throw inputError(path, 0,
                     "cannot write mesh format " + (ext.empty() ? std::string("(no extension)") : io::quoted(ext)) +
                         "; expected .obj, .ply, .off or .stl");
  if (significantDigits < 1 || significantDigits > 17)
    throw Error(ErrorKind::Internal, "writeMesh: significant digits must be 1..17");
  bool withNormals = false;
  checkWritable(path, mesh, withNormals);
  writeFileAtomically(
      path,
      [&](std::ostream& os) {
        if (ext == ".obj") writeObj(os, mesh, significantDigits, withNormals);
        else if (ext == ".ply") writePly(os, mesh, significantDigits, withNormals);
        else if (ext == ".off") writeOff(os, mesh, significantDigits);
        else writeStl(os, mesh, significantDigits, withNormals);
      },
      true);
}

}  // namespace sffd
