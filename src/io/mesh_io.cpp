// Mesh files: dispatch by extension, normals and welding. The writers live in mesh_io_write.cpp,
// the readers in mesh_io_obj.cpp (OBJ), mesh_io_formats.cpp (OFF, PLY, STL), mesh_io_om.cpp
// (OpenMesh .om) and mesh_io_bpt.cpp (Bezier patches).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <ostream>

#include "io/atomic_file.h"
#include "io/gltf_io.h"
#include <sffd/error.h>
#include "io/io_util.h"
#include "model/mesh.h"
#include "io/mesh_io_internal.h"

namespace sffd {

Mesh readMesh(const std::string& path, const MeshReadOptions& options) {
  std::string ext = io::lowerExtension(path);
  static const char* known[] = {".obj", ".off", ".ply", ".stl", ".om", ".bpt", ".gltf", ".glb"};
  bool ok = false;
  for (const char* k : known) ok = ok || ext == k;
  if (path.empty()) throw Error(ErrorKind::Input, "the mesh's file name is empty");
  try {
    if (!ok)
      throw inputError(path, 0,
                       "unknown mesh format " + (ext.empty() ? std::string("(no extension)") : io::quoted(ext)) +
                           "; expected .obj, .off, .ply, .stl, .om, .bpt, .gltf or .glb");
    return meshio::readMeshBytes(path, io::readWholeFile(path), options);
  } catch (const Error& e) {
    throw Error(e.kind(), io::oneLine(e.what()));   // a file name with a newline still makes one line
  }
}

namespace meshio {

bool readsInForkedChild(const std::string& path) { return io::lowerExtension(path) == ".om"; }

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
  if (readsInForkedChild(path)) return readOm(path, text);
  if (ext == ".bpt") return readBpt(path, text, options);
  if (ext == ".gltf" || ext == ".glb") return readGltf(path, text);
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

}  // namespace

std::vector<uint32_t> meshio::distinctPositions(const std::vector<glm::dvec3>& positions, uint32_t& count) {
  Key3Map ids(positions.size());
  std::vector<uint32_t> id(positions.size());
  count = 0;
  for (size_t v = 0; v < positions.size(); ++v) {
    id[v] = ids.of(bitsKey(positions[v]), count);
    count += id[v] == count;
  }
  return id;
}

void computeVertexNormals(Mesh& mesh) {
  std::vector<glm::dvec3> sum = angleWeightedSums(mesh);
  mesh.normals.resize(mesh.positions.size());
  for (size_t v = 0; v < sum.size(); ++v) mesh.normals[v] = unitOrZ(sum[v]);
}

void weldPositions(Mesh& mesh) {
  uint32_t count = 0;
  mesh.weldId = meshio::distinctPositions(mesh.positions, count);
}

namespace meshio {

void finishMesh(Mesh& mesh, const std::vector<uint8_t>& fromFile, const std::string& path, const std::vector<uint32_t>& normalShared) {
  const size_t n = mesh.positions.size();
  if (mesh.triangles.empty()) throw inputError(path, 0, "no triangles");   // a file's (a Deformer takes an empty Mesh)
  mesh.normals.resize(n, glm::dvec3(0.0));
  validateMesh(mesh, path, /*normals=*/false);   // unset or non-finite file normals are recomputed below
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
    if (normalShared.size() == n) {   // vertices split by another value (a texture seam) share one normal
      for (size_t v = 0; v < n; ++v)
        if (compute[v] && normalShared[v] != v) sum[normalShared[v]] += sum[v];
      for (size_t v = 0; v < n; ++v)
        if (compute[v] && normalShared[v] != v) sum[v] = sum[normalShared[v]];
    }
    for (size_t v = 0; v < n; ++v)
      if (compute[v]) mesh.normals[v] = unitOrZ(sum[v]);
  }
  mesh.normalsFromFile = anyFromFile;
  weldPositions(mesh);
}

}  // namespace meshio

}  // namespace sffd
