// Wavefront OBJ reader. OpenMesh's OBJ reader keeps one normal per position and so loses split normals
// (a position used with different `vn` in different faces, e.g. a cube with face normals); this one keeps
// them: every distinct (position, normal) pair used by a face corner is a vertex.
//
// Read: `v x y z [w]`, `vn x y z`, `vt ...` (counted, for index checks), `f` with corners `v`, `v/vt`,
// `v//vn`, `v/vt/vn`, 1-based or negative (relative) indices, polygons fan-triangulated, `\` line
// continuations, `#` comments. Every other statement is ignored.
// Vertex order: vertex i is position i (with the first normal a face uses it with; unreferenced positions
// are kept), and each further normal of a position adds a vertex after all positions.
#include <cmath>
#include <cstring>
#include <unordered_map>

#include <sffd/error.h>
#include "io/io_util.h"
#include "io/mesh_io_internal.h"

namespace sffd::meshio {
namespace {

struct Corner {
  int64_t p, t, n;   // 0-based; t, n: -1 when absent
};

struct NormalKeyHash {
  size_t operator()(const std::array<uint64_t, 3>& k) const {
    uint64_t h = k[0] * 0x9E3779B97F4A7C15ull;
    h ^= k[1] + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= k[2] + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
    return size_t(h);
  }
};

}  // namespace

Mesh readObj(const std::string& path, const std::string& text) {
  size_t dropped = 0;   // polygons without area (addPolygon)
  std::vector<size_t> emptyFaceLines;
  std::vector<glm::dvec3> pos, nrm;
  int64_t vtCount = 0;
  std::vector<Corner> corners;
  std::vector<uint64_t> faceStart;   // into corners; one extra at the end
  std::vector<size_t> faceLine;
  std::vector<std::string_view> tok;
  std::string joined;   // a logical line made of continued physical lines

  auto fail = [&](size_t line, const std::string& what) { return inputError(path, line, what); };

  auto readVec = [&](size_t line, const char* what) {
    if (tok.size() < 4) throw fail(line, std::string(what) + " needs 3 coordinates");
    glm::dvec3 v;
    for (int c = 0; c < 3; ++c) {
      if (!io::parseDouble(tok[1 + c], v[c])) throw fail(line, "bad number " + io::quoted(tok[1 + c]));
      if (!std::isfinite(v[c])) throw fail(line, "non-finite coordinate " + io::quoted(tok[1 + c]));
    }
    return v;
  };
  // One index field of a face corner: 1-based, or negative relative to the `count` items so far.
  auto index = [&](std::string_view field, int64_t count, size_t line, const char* kind) -> int64_t {
    long long i = 0;
    if (!io::parseInt(field, i)) throw fail(line, std::string("bad ") + kind + " index " + io::quoted(field));
    if (i == 0) throw fail(line, std::string(kind) + " index 0 (OBJ indices start at 1)");
    if (i < 0) {
      if (-i > count)
        throw fail(line, std::string("relative ") + kind + " index " + std::to_string(i) + " refers before the first " + kind);
      return count + i;
    }
    return i - 1;   // checked against the final count once the file is read
  };

  io::LineReader lines(text);
  std::string_view raw;
  size_t lineNo = 0;
  while (lines.next(raw, lineNo)) {
    size_t line = lineNo;
    std::string_view l = raw;
    if (!l.empty() && l.back() == '\\') {   // continuation lines
      joined.assign(l.substr(0, l.size() - 1));
      size_t more = 0;
      std::string_view next;
      while (lines.next(next, more)) {
        if (!next.empty() && next.back() == '\\') {
          joined += ' ';
          joined.append(next.substr(0, next.size() - 1));
          continue;
        }
        joined += ' ';
        joined.append(next);
        break;
      }
      l = joined;
    }
    size_t hash = l.find('#');
    if (hash != std::string_view::npos) l = l.substr(0, hash);
    io::splitTokens(l, tok);
    if (tok.empty()) continue;
    std::string_view kw = tok[0];
    if (kw == "v") {
      pos.push_back(readVec(line, "vertex"));
      if (pos.size() > kMaxVertices) throw fail(line, "too many vertices");
    } else if (kw == "vn") {
      nrm.push_back(readVec(line, "normal"));
    } else if (kw == "vt") {
      ++vtCount;
    } else if (kw == "f") {
      size_t n = tok.size() - 1;
      if (n == 0) {   // skipped, as Assimp, MeshLab and Blender do
        emptyFaceLines.push_back(line);
        continue;
      }
      if (n < 3) throw fail(line, "face with " + std::to_string(n) + " vertices (at least 3 needed)");
      faceStart.push_back(corners.size());
      faceLine.push_back(line);
      for (size_t c = 1; c < tok.size(); ++c) {
        std::string_view f = tok[c];
        std::string_view fields[3];
        int nf = 0;
        size_t s = 0;
        while (true) {
          size_t slash = f.find('/', s);
          if (nf == 3) throw fail(line, "bad face corner " + io::quoted(f));
          fields[nf++] = f.substr(s, slash == std::string_view::npos ? std::string_view::npos : slash - s);
          if (slash == std::string_view::npos) break;
          s = slash + 1;
        }
        Corner k{index(fields[0], int64_t(pos.size()), line, "vertex"), -1, -1};
        if (nf >= 2 && !fields[1].empty()) k.t = index(fields[1], vtCount, line, "texture coordinate");
        if (nf >= 3) {
          if (fields[2].empty()) throw fail(line, "bad face corner " + io::quoted(f));
          k.n = index(fields[2], int64_t(nrm.size()), line, "normal");
        }
        corners.push_back(k);
      }
    }
    // every other statement (vt values, o, g, s, usemtl, mtllib, l, p, ...) is ignored
  }
  if (faceStart.empty()) throw inputError(path, 0, "no faces");
  faceStart.push_back(corners.size());

  // Index ranges (positive indices may refer forward, so they are checked here).
  for (size_t f = 0; f + 1 < faceStart.size(); ++f)
    for (uint64_t c = faceStart[f]; c < faceStart[f + 1]; ++c) {
      const Corner& k = corners[c];
      if (k.p >= int64_t(pos.size()))
        throw fail(faceLine[f], "vertex index " + std::to_string(k.p + 1) + " out of range (" + std::to_string(pos.size()) + " vertices)");
      if (k.t >= vtCount)
        throw fail(faceLine[f], "texture coordinate index " + std::to_string(k.t + 1) + " out of range (" +
                                    std::to_string(vtCount) + " texture coordinates)");
      if (k.n >= int64_t(nrm.size()))
        throw fail(faceLine[f], "normal index " + std::to_string(k.n + 1) + " out of range (" + std::to_string(nrm.size()) + " normals)");
    }

  // Equal normal values count as the same normal.
  std::vector<int64_t> canon(nrm.size());
  {
    std::unordered_map<std::array<uint64_t, 3>, int64_t, NormalKeyHash> first;
    for (size_t i = 0; i < nrm.size(); ++i) {
      std::array<uint64_t, 3> key;
      for (int c = 0; c < 3; ++c) {
        double d = nrm[i][c] + 0.0;
        std::memcpy(&key[c], &d, 8);
      }
      canon[i] = first.emplace(key, int64_t(i)).first->second;
    }
  }

  Mesh mesh;
  mesh.positions = pos;
  std::vector<int64_t> slot(pos.size(), -2);   // normal slot of the primary vertex: -2 unused, -1 none
  std::unordered_map<uint64_t, uint32_t> extra;   // (position, normal slot + 1) -> vertex
  std::vector<uint32_t> vid;
  mesh.triangles.reserve(corners.size());
  for (size_t f = 0; f + 1 < faceStart.size(); ++f) {
    vid.clear();
    for (uint64_t c = faceStart[f]; c < faceStart[f + 1]; ++c) {
      const Corner& k = corners[c];
      int64_t s = k.n >= 0 ? canon[k.n] : -1;
      uint32_t v;
      if (slot[k.p] == -2 || slot[k.p] == s) {
        slot[k.p] = s;
        v = uint32_t(k.p);
      } else {
        uint64_t key = (uint64_t(k.p) << 32) ^ uint64_t(s + 1);
        auto it = extra.find(key);
        if (it == extra.end()) {
          if (mesh.positions.size() >= kMaxVertices) throw fail(faceLine[f], "too many vertices");
          it = extra.emplace(key, uint32_t(mesh.positions.size())).first;
          mesh.positions.push_back(pos[k.p]);
          slot.push_back(s);
        }
        v = it->second;
      }
      vid.push_back(v);
    }
    addPolygon(mesh, vid.data(), vid.size(), dropped);
  }
  mesh.normals.assign(mesh.positions.size(), glm::dvec3(0.0));
  std::vector<uint8_t> fromFile(mesh.positions.size(), 0);
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    if (slot[v] >= 0) {
      mesh.normals[v] = nrm[size_t(slot[v])];
      fromFile[v] = 1;
    }
  noteDroppedPolygons(mesh, dropped);
  if (!emptyFaceLines.empty())
    mesh.warnings.push_back(path + ":" + std::to_string(emptyFaceLines[0]) + ": " + std::to_string(emptyFaceLines.size()) +
                            (emptyFaceLines.size() == 1 ? " empty face line" : " empty face lines") + " skipped");
  finishMesh(mesh, fromFile, path);
  return mesh;
}

}  // namespace sffd::meshio
