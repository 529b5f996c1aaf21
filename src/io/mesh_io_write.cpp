// Mesh writers: .obj .ply .off .stl, text (numbers by std::to_chars with a fixed count of significant
// digits) or, for .ply and .stl, binary little-endian; .gltf and .glb in gltf_write.cpp. Output is built
// in a buffer handed to the stream in large pieces (a large mesh never sits in memory twice).
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <ostream>

#include <sffd/error.h>

#include "io/atomic_file.h"
#include "io/gltf_io.h"
#include "io/io_util.h"
#include "io/mesh_io_internal.h"
#include "model/mesh.h"
#include "io/mesh_write_records.h"

namespace sffd {
namespace {

static_assert(std::endian::native == std::endian::little, "the binary writers copy little-endian values as they are");

class ChunkedWriter {
 public:
  explicit ChunkedWriter(std::ostream& os) : os_(os) { buf_.reserve(kChunk + 4096); }
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

void appendIndex(std::string& s, uint64_t i) {
  char b[24];
  s.append(b, std::to_chars(b, b + sizeof b, i).ptr);
}

template <class T>
void appendRaw(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  s.append(b, sizeof(T));
}

uint8_t colorByte(double c) { return uint8_t(std::lround(std::clamp(c, 0.0, 1.0) * 255.0)); }

constexpr size_t kBlock = 4096;   // records writePly and writeStl append between flushes

}  // namespace

namespace meshio {

void throwBadVertex(const std::string& path, size_t v, const glm::dvec3& position, const glm::dvec3* normal, bool floats) {
  auto finite = [](const glm::dvec3& x) { return std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z); };
  if (finite(position) && (!normal || finite(*normal)) && floats)
    throw Error(ErrorKind::Input, path + ": not written: vertex " + std::to_string(v) +
                                      " of the result lies beyond the range of the file's floats (a text file holds it)");
  throw Error(ErrorKind::Input, path + ": not written: vertex " + std::to_string(v) + " of the result has a " +
                                    (finite(position) ? "non-finite normal" : "non-finite position") +
                                    " (the lattice moves it beyond the floating-point range of the computation)");
}

std::string plyHeader(size_t vertices, size_t faces, int digits, const Carried& has, bool binary) {
  const char* type = digits > 9 ? "double" : "float";
  std::string s = binary ? "ply\nformat binary_little_endian 1.0\n" : "ply\nformat ascii 1.0\n";
  s += "comment written by sffd\n";
  s += "element vertex " + std::to_string(vertices) + "\n";
  auto properties = [&](std::initializer_list<const char*> names, const char* t) {
    for (const char* c : names) s += std::string("property ") + t + " " + c + "\n";
  };
  properties({"x", "y", "z"}, type);
  if (has.normals) properties({"nx", "ny", "nz"}, type);
  if (has.texcoords) properties({"u", "v"}, type);
  if (has.colors) properties({"red", "green", "blue"}, "uchar");
  if (has.alpha) properties({"alpha"}, "uchar");
  s += "element face " + std::to_string(faces) + "\n";
  s += "property list uchar int vertex_indices\nend_header\n";
  return s;
}

namespace {
void appendPlyVertexText(std::string& s, const Mesh& mesh, size_t v, int digits, const Carried& has) {
  appendVec(s, mesh.positions[v], digits);
  if (has.normals) {
    s += ' ';
    appendVec(s, mesh.normals[v], digits);
  }
  for (int c = 0; has.texcoords && c < 2; ++c) {
    s += ' ';
    io::appendNumber(s, mesh.texcoords[v][c], digits);
  }
  for (int c = 0; has.colors && c < (has.alpha ? 4 : 3); ++c) {
    s += ' ';
    appendIndex(s, colorByte(mesh.colors[v][c]));
  }
  s += '\n';
}

// Binary records are written in place, in room made for all of them: appended field by field (a size
// check and a copy of 4 bytes each) they cost as much as the weld beside them.
template <class Real>
void appendPlyVerticesBinary(std::string& s, const Mesh& mesh, size_t first, size_t count, const Carried& has) {
  const int colorChannels = has.alpha ? 4 : 3;
  const size_t record = sizeof(Real) * (3 + (has.normals ? 3 : 0) + (has.texcoords ? 2 : 0)) + (has.colors ? colorChannels : 0);
  const size_t at = s.size();
  s.resize(at + count * record);
  char* p = s.data() + at;
  auto put = [&p](double x) {
    const Real r = Real(x);
    std::memcpy(p, &r, sizeof r);
    p += sizeof r;
  };
  for (size_t v = first; v < first + count; ++v) {
    const glm::dvec3& x = mesh.positions[v];
    put(x.x), put(x.y), put(x.z);
    if (has.normals) {
      const glm::dvec3& n = mesh.normals[v];
      put(n.x), put(n.y), put(n.z);
    }
    if (has.texcoords) put(mesh.texcoords[v].x), put(mesh.texcoords[v].y);
    for (int c = 0; has.colors && c < colorChannels; ++c) *p++ = char(colorByte(mesh.colors[v][c]));
  }
}
}  // namespace

void appendPlyVertices(std::string& s, const Mesh& mesh, size_t first, size_t count, int digits, const Carried& has,
                       bool binary) {
  if (!binary) {
    for (size_t v = first; v < first + count; ++v) appendPlyVertexText(s, mesh, v, digits, has);
  } else if (digits > 9) {
    appendPlyVerticesBinary<double>(s, mesh, first, count, has);
  } else {
    appendPlyVerticesBinary<float>(s, mesh, first, count, has);
  }
}

void appendPlyFaces(std::string& s, const std::array<uint32_t, 3>* triangles, size_t count, bool binary) {
  if (!binary) {
    for (size_t f = 0; f < count; ++f) {
      s += '3';
      for (uint32_t i : triangles[f]) {
        s += ' ';
        appendIndex(s, i);
      }
      s += '\n';
    }
    return;
  }
  // A count byte, then the three indices as int: an index's uint32_t bits are its int's.
  const size_t at = s.size();
  s.resize(at + 13 * count);
  char* p = s.data() + at;
  for (size_t f = 0; f < count; ++f, p += 13) {
    p[0] = 3;
    std::memcpy(p + 1, triangles[f].data(), 12);
  }
}

std::string stlHeader(bool binary, size_t triangles) {
  if (!binary) return "solid sffd\n";
  std::string header = "binary STL written by sffd";   // not "solid ...": readers would take it for text
  header.resize(80, ' ');
  appendRaw(header, uint32_t(triangles));
  return header;
}

std::string stlFooter(bool binary) { return binary ? "" : "endsolid sffd\n"; }

namespace {
// The facet normal STL stores: the geometric one, or the mean vertex normal for a degenerate triangle.
glm::dvec3 facetNormal(const Mesh& mesh, const std::array<uint32_t, 3>& t, bool withNormals) {
  const glm::dvec3& a = mesh.positions[t[0]];
  glm::dvec3 fn = glm::cross(mesh.positions[t[1]] - a, mesh.positions[t[2]] - a);
  double len = glm::length(fn);
  if (len > 0 && std::isfinite(len)) return fn / len;
  if (!withNormals) return glm::dvec3(0.0);
  fn = mesh.normals[t[0]] + mesh.normals[t[1]] + mesh.normals[t[2]];
  len = glm::length(fn);
  return (len > 0 && std::isfinite(len)) ? fn / len : glm::dvec3(0.0);
}
}  // namespace

void appendStlFacets(std::string& s, const Mesh& mesh, const std::array<uint32_t, 3>* triangles, size_t count,
                     bool withNormals, int digits, bool binary) {
  if (binary) {   // 50 bytes a facet, written in place as the PLY records are
    const size_t at = s.size();
    s.resize(at + 50 * count);
    char* p = s.data() + at;
    auto vec = [&p](const glm::dvec3& v) {
      const float f[3] = {float(v.x), float(v.y), float(v.z)};
      std::memcpy(p, f, 12);
      p += 12;
    };
    for (size_t f = 0; f < count; ++f) {
      vec(facetNormal(mesh, triangles[f], withNormals));
      for (uint32_t i : triangles[f]) vec(mesh.positions[i]);
      *p++ = 0, *p++ = 0;   // attribute byte count
    }
    return;
  }
  // Text, so that coordinates keep `digits` digits.
  for (size_t f = 0; f < count; ++f) {
    s += "  facet normal ";
    appendVec(s, facetNormal(mesh, triangles[f], withNormals), digits);
    s += "\n    outer loop\n";
    for (uint32_t i : triangles[f]) {
      s += "      vertex ";
      appendVec(s, mesh.positions[i], digits);
      s += '\n';
    }
    s += "    endloop\n  endfacet\n";
  }
}

}  // namespace meshio

namespace {
using namespace meshio;

meshio::Carried checkWritable(const std::string& path, const Mesh& mesh, bool floats) {
  const size_t n = mesh.positions.size();
  checkMeshStructure(mesh, path);   // a caller's mistake: an input error naming the field
  meshio::Carried c;
  c.normals = !mesh.normals.empty();
  c.texcoords = !mesh.texcoords.empty();
  c.colors = !mesh.colors.empty();
  for (const glm::dvec4& k : mesh.colors) c.alpha = c.alpha || k.a != 1.0;
  // A lattice that sends points beyond the floating-point range gives inf or NaN: refuse to write a
  // file of them, and say where (the lattice is the input at fault, so this is an input error).
  for (size_t v = 0; v < n; ++v) checkFiniteVertex(path, v, mesh.positions[v], c.normals ? &mesh.normals[v] : nullptr, floats);
  return c;
}

// Per vertex the index of the position it is written as (numbered by first appearance), and their count:
// the mesh's locations when it names them (Mesh::weldIdIsLocation: no hash of the positions, and two
// locations at one position stay two), else its distinct position bits.
std::vector<uint32_t> positionIds(const Mesh& mesh, uint32_t& count) {
  const size_t n = mesh.positions.size();
  constexpr uint32_t kNone = ~0u;
  std::vector<uint32_t> id(n), first;   // first: per location, its first vertex
  bool usable = mesh.weldIdIsLocation && mesh.weldId.size() == n;
  if (usable) first.assign(n, kNone);
  count = 0;
  for (size_t v = 0; usable && v < n; ++v) {
    const uint32_t w = mesh.weldId[v];
    if (w >= n) usable = false;
    else if (first[w] == kNone) first[w] = uint32_t(v), id[v] = count++;
    else if (std::memcmp(&mesh.positions[v], &mesh.positions[first[w]], sizeof(glm::dvec3)) == 0) id[v] = id[first[w]];
    else usable = false;
  }
  return usable ? id : meshio::distinctPositions(mesh.positions, count);
}

// A `v` line holds one colour: the vertices at one position whose colour differs from its first vertex's (a
// colour seam) get a line of their own per colour, numbered by first appearance as positionIds numbers.
std::vector<uint32_t> splitByColour(const std::vector<uint32_t>& pid, const Mesh& mesh, uint32_t& count) {
  constexpr uint32_t kNone = ~0u;
  auto bits = [&](size_t v) {
    const glm::dvec4& c = mesh.colors[v];
    return std::array<uint64_t, 3>{std::bit_cast<uint64_t>(c.r), std::bit_cast<uint64_t>(c.g), std::bit_cast<uint64_t>(c.b)};
  };
  std::vector<uint32_t> first(count, kNone), id(pid.size());
  std::map<std::pair<uint32_t, std::array<uint64_t, 3>>, uint32_t> more;   // a position's further colours: their ids
  uint32_t next = 0;
  for (size_t v = 0; v < pid.size(); ++v) {
    const uint32_t p = pid[v];
    if (first[p] == kNone) {
      first[p] = uint32_t(v);
      id[v] = next++;
    } else if (bits(v) == bits(first[p])) {
      id[v] = id[first[p]];
    } else {
      auto [it, fresh] = more.try_emplace({p, bits(v)}, next);
      next += fresh;
      id[v] = it->second;
    }
  }
  count = next;
  return id;
}

void writeObj(std::ostream& os, const Mesh& mesh, int digits, const Carried& has) {
  // Positions are written once per location or distinct value (so a welded mesh stays welded for every OBJ reader),
  // and per colour there (splitByColour), texture coordinates and normals once per vertex; a face corner is
  // "position/vertex/vertex".
  uint32_t count = 0;
  std::vector<uint32_t> pid = positionIds(mesh, count);
  if (has.colors) pid = splitByColour(pid, mesh, count);
  ChunkedWriter w(os);
  std::string& s = w.buf();
  s += "# sffd mesh: " + std::to_string(count) + " positions, " + std::to_string(mesh.positions.size()) + " vertices, " +
       std::to_string(mesh.triangles.size()) + " triangles\n";
  for (const std::string& lib : mesh.materialLibraries) s += "mtllib " + lib + "\n";
  uint32_t next = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    if (pid[v] != next) continue;   // written already
    ++next;
    s += "v ";
    appendVec(s, mesh.positions[v], digits);
    if (has.colors) {   // the common "v x y z r g b" extension (MeshLab, Blender)
      s += ' ';
      appendVec(s, glm::dvec3(mesh.colors[v]), digits);
    }
    s += '\n';
    w.maybeFlush();
  }
  if (has.texcoords)
    for (const glm::dvec2& t : mesh.texcoords) {
      s += "vt ";
      io::appendNumber(s, t.x, digits);
      s += ' ';
      io::appendNumber(s, t.y, digits);
      s += '\n';
      w.maybeFlush();
    }
  if (has.normals)
    for (const auto& nrm : mesh.normals) {
      s += "vn ";
      appendVec(s, nrm, digits);
      s += '\n';
      w.maybeFlush();
    }
  uint32_t group = Mesh::kNoIndex, material = Mesh::kNoIndex;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (!mesh.triangleGroup.empty() && mesh.triangleGroup[f] != group) {
      group = mesh.triangleGroup[f];
      s += "g " + (group == Mesh::kNoIndex ? std::string("default") : mesh.groups[group]) + "\n";
    }
    if (!mesh.triangleMaterial.empty() && mesh.triangleMaterial[f] != material && mesh.triangleMaterial[f] != Mesh::kNoIndex) {
      material = mesh.triangleMaterial[f];
      s += "usemtl " + mesh.materials[material].name + "\n";
    }
    s += 'f';
    for (uint32_t i : mesh.triangles[f]) {
      s += ' ';
      appendIndex(s, pid[i] + 1);
      if (has.texcoords || has.normals) s += '/';
      if (has.texcoords) appendIndex(s, i + 1);
      if (has.normals) {
        s += '/';
        appendIndex(s, i + 1);
      }
    }
    s += '\n';
    w.maybeFlush();
  }
  w.flush();
}

void writePly(std::ostream& os, const Mesh& mesh, int digits, const Carried& has, bool binary) {
  ChunkedWriter w(os);
  std::string& s = w.buf();
  s += plyHeader(mesh.positions.size(), mesh.triangles.size(), digits, has, binary);
  for (size_t v = 0; v < mesh.positions.size(); v += kBlock) {
    appendPlyVertices(s, mesh, v, std::min(kBlock, mesh.positions.size() - v), digits, has, binary);
    w.maybeFlush();
  }
  for (size_t f = 0; f < mesh.triangles.size(); f += kBlock) {
    appendPlyFaces(s, &mesh.triangles[f], std::min(kBlock, mesh.triangles.size() - f), binary);
    w.maybeFlush();
  }
  w.flush();
}

void writeOff(std::ostream& os, const Mesh& mesh, int digits) {
  // OFF holds positions only: one per location or distinct position, so a welded mesh stays welded.
  uint32_t count = 0;
  std::vector<uint32_t> pid = positionIds(mesh, count);
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
    s += '3';
    for (uint32_t i : t) {
      s += ' ';
      appendIndex(s, pid[i]);
    }
    s += '\n';
    w.maybeFlush();
  }
  w.flush();
}

void writeStl(std::ostream& os, const Mesh& mesh, int digits, bool withNormals, bool binary) {
  if (binary && mesh.triangles.size() > 0xFFFFFFFFull) throw Error(ErrorKind::Input, "binary STL holds at most 2^32 - 1 triangles");
  ChunkedWriter w(os);
  std::string& s = w.buf();
  s += stlHeader(binary, mesh.triangles.size());
  for (size_t f = 0; f < mesh.triangles.size(); f += kBlock) {
    appendStlFacets(s, mesh, &mesh.triangles[f], std::min(kBlock, mesh.triangles.size() - f), withNormals, digits, binary);
    w.maybeFlush();
  }
  s += stlFooter(binary);
  w.flush();
}

}  // namespace

void writeMesh(const std::string& path, const Mesh& mesh, int significantDigits) {
  writeMesh(path, mesh, MeshWriteOptions{significantDigits, false});
}

std::string meshio::checkWriteTarget(const std::string& path, const MeshWriteOptions& options) {
  const std::string ext = io::lowerExtension(path);
  const bool gltf = ext == ".gltf" || ext == ".glb";
  if (ext != ".obj" && ext != ".ply" && ext != ".off" && ext != ".stl" && !gltf)
    throw inputError(path, 0,
                     "cannot write mesh format " + (ext.empty() ? std::string("(no extension)") : io::quoted(ext)) +
                         "; expected .obj, .ply, .off, .stl, .gltf or .glb");
  if (options.binary && ext != ".ply" && ext != ".stl")
    throw inputError(path, 0, "binary output is for .ply and .stl (.glb is binary glTF), not " + io::quoted(ext));
  if (options.significantDigits < 1 || options.significantDigits > 17)
    throw inputError(path, 0, "MeshWriteOptions::significantDigits must be 1..17, not " + std::to_string(options.significantDigits));
  return ext;
}

void writeMesh(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options) {
  const std::string ext = meshio::checkWriteTarget(path, options);
  const bool gltf = ext == ".gltf" || ext == ".glb";
  const int digits = options.significantDigits;
  const Carried has = checkWritable(path, mesh, ext == ".stl" && options.binary);
  if (gltf) return meshio::writeGltf(path, mesh);
  writeFileAtomically(
      path,
      [&](std::ostream& os) {
        if (ext == ".obj") writeObj(os, mesh, digits, has);
        else if (ext == ".ply") writePly(os, mesh, digits, has, options.binary);
        else if (ext == ".off") writeOff(os, mesh, digits);
        else writeStl(os, mesh, digits, has.normals, options.binary);
      },
      true);
}

}  // namespace sffd
