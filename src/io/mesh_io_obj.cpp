// Wavefront OBJ reader. OpenMesh's OBJ reader keeps one normal per position and so loses split normals
// (a position used with different `vn` in different faces, e.g. a cube with face normals); this one keeps
// them: every distinct (position, normal) pair used by a face corner is a vertex.
//
// Read: `v x y z [w]` or `v x y z r g b` (vertex colours), `vn x y z`, `vt u [v [w]]`, `f` with corners
// `v`, `v/vt`, `v//vn`, `v/vt/vn`, 1-based or negative (relative) indices, polygons triangulated, `g`,
// `usemtl`, `mtllib` (the .mtl files beside the OBJ give each material's Kd, d and map_Kd), `\` line
// continuations, `#` comments. Every other statement is ignored.
// Vertex order: vertex i is position i (with the first normal and texture coordinate a face uses it with;
// unreferenced positions are kept), and each further (normal, texture coordinate) pair of a position adds
// a vertex after all positions.
#include <cmath>
#include <cstring>
#include <filesystem>

#include <sffd/error.h>
#include "io/io_util.h"
#include "io/mesh_io_internal.h"

namespace sffd::meshio {
namespace {

struct Corner {
  int64_t p, t, n;   // 0-based; t, n: -1 when absent
};

// The index of each value's first equal value (bit equality, -0 = +0): equal normals or texture
// coordinates given twice count as one. At most kMaxVertices values.
template <class Vec>
std::vector<int64_t> firstEqual(const std::vector<Vec>& values) {
  std::vector<int64_t> canon(values.size());
  Key3Map first(values.size());
  for (size_t i = 0; i < values.size(); ++i) canon[i] = first.of(bitsKey(values[i]), uint32_t(i));
  return canon;
}

// The index of `name` in `names`, added when new.
uint32_t indexOfName(std::vector<std::string>& names, std::string_view name) {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return uint32_t(i);
  names.emplace_back(name);
  return uint32_t(names.size() - 1);
}

// Kd, d and map_Kd of the materials `mesh` uses, from its material libraries beside `objPath`. A
// library that is not a readable regular file of at most 16 MiB is named in a warning and skipped.
void readMaterialLibraries(Mesh& mesh, const std::string& objPath) {
  namespace fs = std::filesystem;
  std::vector<std::string_view> tok;
  for (const std::string& lib : mesh.materialLibraries) {
    const fs::path p = fs::path(objPath).parent_path() / lib;
    std::error_code ec;
    if (!fs::is_regular_file(p, ec) || fs::file_size(p, ec) > (16u << 20)) {
      mesh.warnings.push_back(objPath + ": material library " + io::quoted(lib) + " not found: materials keep their names only");
      continue;
    }
    std::string text;
    try {
      text = io::readWholeFile(p.string());
    } catch (const Error&) {
      continue;   // empty or unreadable: nothing to take from it
    }
    io::LineReader lines(text);
    std::string_view raw;
    size_t lineNo = 0;
    Material* m = nullptr;
    while (lines.next(raw, lineNo)) {
      io::splitTokens(raw.substr(0, raw.find('#')), tok);
      if (tok.empty()) continue;
      if (tok[0] == "newmtl" && tok.size() >= 2) {
        m = nullptr;
        for (Material& known : mesh.materials)
          if (known.name == tok[1]) m = &known;
      } else if (m && tok[0] == "Kd" && tok.size() >= 4) {
        for (int c = 0; c < 3; ++c) io::parseDouble(tok[1 + c], m->baseColor[c]);
      } else if (m && tok[0] == "d" && tok.size() >= 2) {
        io::parseDouble(tok[1], m->baseColor.a);
      } else if (m && tok[0] == "map_Kd" && tok.size() >= 2) {
        m->baseColorTexture = std::string(tok.back());   // options (-s, -o ...) come before the file name
      }
    }
  }
}

}  // namespace

Mesh readObj(const std::string& path, const std::string& text) {
  size_t dropped = 0;   // polygons without area (addPolygon)
  std::vector<size_t> emptyFaceLines;
  std::vector<glm::dvec3> pos, nrm, posColor;
  std::vector<glm::dvec2> tex;
  bool anyColor = false;
  std::vector<std::string> materialNames, groupNames, libraries;
  uint32_t material = Mesh::kNoIndex, group = Mesh::kNoIndex;
  std::vector<uint32_t> faceMaterial, faceGroup;   // per face
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
      glm::dvec3 rgb(1.0);
      if (tok.size() >= 7) {   // "v x y z r g b": the vertex colour extension
        tok.erase(tok.begin() + 1, tok.begin() + 4);
        rgb = readVec(line, "vertex colour");
        anyColor = true;
      }
      posColor.push_back(rgb);
    } else if (kw == "vn") {
      nrm.push_back(readVec(line, "normal"));
      if (nrm.size() > kMaxVertices) throw fail(line, "too many normals");
    } else if (kw == "vt") {
      if (tok.size() < 2) throw fail(line, "texture coordinate needs a value");
      glm::dvec2 t(0.0);
      for (size_t c = 0; c < 2 && c + 1 < tok.size(); ++c) {
        if (!io::parseDouble(tok[1 + c], t[int(c)])) throw fail(line, "bad number " + io::quoted(tok[1 + c]));
        if (!std::isfinite(t[int(c)])) throw fail(line, "non-finite texture coordinate " + io::quoted(tok[1 + c]));
      }
      tex.push_back(t);
      if (tex.size() > kMaxVertices) throw fail(line, "too many texture coordinates");
    } else if (kw == "usemtl" && tok.size() >= 2) {
      material = indexOfName(materialNames, tok[1]);
    } else if (kw == "g") {
      std::string name;
      for (size_t i = 1; i < tok.size(); ++i) name += (i > 1 ? " " : "") + std::string(tok[i]);
      group = indexOfName(groupNames, name.empty() ? "default" : name);
    } else if (kw == "mtllib") {
      for (size_t i = 1; i < tok.size(); ++i) indexOfName(libraries, tok[i]);
    } else if (kw == "f") {
      size_t n = tok.size() - 1;
      if (n == 0) {   // skipped, as Assimp, MeshLab and Blender do
        emptyFaceLines.push_back(line);
        continue;
      }
      if (n < 3) throw fail(line, "face with " + std::to_string(n) + " vertices (at least 3 needed)");
      faceStart.push_back(corners.size());
      faceLine.push_back(line);
      faceMaterial.push_back(material);
      faceGroup.push_back(group);
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
        if (nf >= 2 && !fields[1].empty()) k.t = index(fields[1], int64_t(tex.size()), line, "texture coordinate");
        if (nf >= 3) {
          if (fields[2].empty()) throw fail(line, "bad face corner " + io::quoted(f));
          k.n = index(fields[2], int64_t(nrm.size()), line, "normal");
        }
        corners.push_back(k);
      }
    }
    // every other statement (o, s, l, p, ...) is ignored
  }
  if (faceStart.empty()) throw inputError(path, 0, "no faces");
  faceStart.push_back(corners.size());

  // Index ranges (positive indices may refer forward, so they are checked here).
  for (size_t f = 0; f + 1 < faceStart.size(); ++f)
    for (uint64_t c = faceStart[f]; c < faceStart[f + 1]; ++c) {
      const Corner& k = corners[c];
      if (k.p >= int64_t(pos.size()))
        throw fail(faceLine[f], "vertex index " + std::to_string(k.p + 1) + " out of range (" + std::to_string(pos.size()) + " vertices)");
      if (k.t >= int64_t(tex.size()))
        throw fail(faceLine[f], "texture coordinate index " + std::to_string(k.t + 1) + " out of range (" +
                                    std::to_string(int64_t(tex.size())) + " texture coordinates)");
      if (k.n >= int64_t(nrm.size()))
        throw fail(faceLine[f], "normal index " + std::to_string(k.n + 1) + " out of range (" + std::to_string(nrm.size()) + " normals)");
    }

  // Equal normal (texture coordinate) values count as the same normal (texture coordinate).
  const std::vector<int64_t> canonN = firstEqual(nrm), canonT = firstEqual(tex);

  // A vertex is a position with one (normal, texture coordinate) pair: its slot, -1 for none.
  struct Slot {
    int64_t n = -2, t = -2;   // -2: the position is not used yet
    bool operator==(const Slot&) const = default;
  };
  Mesh mesh;
  mesh.positions = pos;
  std::vector<Slot> slot(pos.size());
  std::vector<uint32_t> positionOf(pos.size());
  for (size_t i = 0; i < pos.size(); ++i) positionOf[i] = uint32_t(i);
  Key3Map extra(0);   // (position, n + 1, t + 1) -> vertex
  std::vector<uint32_t> vid;
  mesh.triangles.reserve(corners.size());
  const bool perTriangleMaterial = !materialNames.empty(), perTriangleGroup = !groupNames.empty();
  for (size_t f = 0; f + 1 < faceStart.size(); ++f) {
    vid.clear();
    for (uint64_t c = faceStart[f]; c < faceStart[f + 1]; ++c) {
      const Corner& k = corners[c];
      const Slot s{k.n >= 0 ? canonN[size_t(k.n)] : -1, k.t >= 0 ? canonT[size_t(k.t)] : -1};
      uint32_t v;
      if (slot[size_t(k.p)].n == -2 || slot[size_t(k.p)] == s) {
        slot[size_t(k.p)] = s;
        v = uint32_t(k.p);
      } else {
        const uint32_t next = uint32_t(mesh.positions.size());
        v = extra.of({uint64_t(k.p), uint64_t(s.n + 1), uint64_t(s.t + 1)}, next);
        if (v == next) {
          if (mesh.positions.size() >= kMaxVertices) throw fail(faceLine[f], "too many vertices");
          mesh.positions.push_back(pos[size_t(k.p)]);
          slot.push_back(s);
          positionOf.push_back(uint32_t(k.p));
        }
      }
      vid.push_back(v);
    }
    addPolygon(mesh, vid.data(), vid.size(), dropped);
    if (perTriangleMaterial) mesh.triangleMaterial.resize(mesh.triangles.size(), faceMaterial[f]);
    if (perTriangleGroup) mesh.triangleGroup.resize(mesh.triangles.size(), faceGroup[f]);
  }
  const size_t n = mesh.positions.size();
  mesh.normals.assign(n, glm::dvec3(0.0));
  std::vector<uint8_t> fromFile(n, 0);
  bool anyTexcoord = false;
  for (size_t v = 0; v < n; ++v) {
    if (slot[v].n >= 0) {
      mesh.normals[v] = nrm[size_t(slot[v].n)];
      fromFile[v] = 1;
    }
    anyTexcoord = anyTexcoord || slot[v].t >= 0;
  }
  if (anyTexcoord) {   // corners without one get (0, 0), as Blender reads them
    mesh.texcoords.assign(n, glm::dvec2(0.0));
    for (size_t v = 0; v < n; ++v)
      if (slot[v].t >= 0) mesh.texcoords[v] = tex[size_t(slot[v].t)];
  }
  if (anyColor)
    for (size_t v = 0; v < n; ++v) mesh.colors.push_back(glm::dvec4(posColor[positionOf[v]], 1.0));
  for (const std::string& name : materialNames) {
    Material m;
    m.name = name;
    mesh.materials.push_back(std::move(m));
  }
  mesh.groups = std::move(groupNames);
  mesh.materialLibraries = std::move(libraries);
  if (!mesh.materialLibraries.empty() && !mesh.materials.empty()) readMaterialLibraries(mesh, path);
  noteDroppedPolygons(mesh, dropped);
  if (!emptyFaceLines.empty())
    mesh.warnings.push_back(path + ":" + std::to_string(emptyFaceLines[0]) + ": " + std::to_string(emptyFaceLines.size()) +
                            (emptyFaceLines.size() == 1 ? " empty face line" : " empty face lines") + " skipped");
  // A position used without `vn` by corners with different `vt` gets one computed normal (a texture
  // seam is no crease).
  std::vector<uint32_t> normalShared(n);
  std::vector<int64_t> firstWithout(pos.size(), -1);
  for (size_t v = 0; v < n; ++v) {
    normalShared[v] = uint32_t(v);
    if (slot[v].n != -1) continue;
    int64_t& first = firstWithout[positionOf[v]];
    if (first < 0) first = int64_t(v);
    normalShared[v] = uint32_t(first);
  }
  finishMesh(mesh, fromFile, path, normalShared);
  return mesh;
}

}  // namespace sffd::meshio
