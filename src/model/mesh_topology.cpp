// Mesh preparation for smooth FFD (METHOD.md 3.1, 3.2): triangle adjacency by welded position,
// crease detection from split normals, per-corner neighbour normals, and the crease-angle fallback.
//
// Implements the input model of Cui & Feng, "Smooth free-form deformation with sharp feature
// awareness" (2015), as its authors' code builds it (albuscrow/acaffd, `mvc_model/model.py`:
// adjacency by position index; `previous_compute_shader_pn_oo.glsl`: a corner is sharp when the two
// faces of an edge carry different normals there, compared per component with tolerance 1e-6). The
// papers use no feature angle; `applyCreaseAngle` is the spec's reconstruction [R] for meshes that
// come without normals: smoothing fans separated by edges whose dihedral angle exceeds a threshold.
#include "model/mesh_topology.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <unordered_map>

#include <sffd/error.h>

namespace sffd {

namespace {

void checkMesh(const Mesh& mesh, const char* who, bool needNormals) {
  const size_t n = mesh.positions.size();
  if (mesh.weldId.size() != n)
    throw Error(ErrorKind::Internal, std::string(who) + ": weldId has " + std::to_string(mesh.weldId.size()) +
                                         " entries for " + std::to_string(n) + " vertices");
  if (needNormals && mesh.normals.size() != n)
    throw Error(ErrorKind::Internal, std::string(who) + ": normals has " + std::to_string(mesh.normals.size()) +
                                         " entries for " + std::to_string(n) + " vertices");
  for (const auto& t : mesh.triangles)
    for (uint32_t v : t)
      if (v >= n) throw Error(ErrorKind::Internal, std::string(who) + ": triangle vertex index out of range");
}

}  // namespace

// Left out of the adjacency altogether: counting its edges would turn the real edge it lies on into a
// non-manifold one and disconnect the two proper triangles there (which, the collapsed one having no
// area, really are neighbours).
bool weldDegenerate(const Mesh& mesh, const std::array<uint32_t, 3>& t) {
  return weldsCollapsed(mesh.weldId[t[0]], mesh.weldId[t[1]], mesh.weldId[t[2]]);
}

namespace {

struct Adjacency {
  std::vector<std::array<int32_t, 3>> neighbour;
  std::vector<std::array<int8_t, 3>> neighbourEdge;
  size_t boundaryEdges = 0, nonManifoldEdges = 0;
};

// Pairs the triangles of each undirected welded edge. Sorting the (edge key, triangle, edge) records
// groups equal keys and makes the result independent of any hash order.
Adjacency weldedAdjacency(const Mesh& mesh) {
  const size_t T = mesh.triangles.size();
  Adjacency adj;
  adj.neighbour.assign(T, {-1, -1, -1});
  adj.neighbourEdge.assign(T, {-1, -1, -1});

  struct Record {
    uint64_t key;
    uint32_t tri;
    uint32_t edge;
    bool operator<(const Record& o) const {
      if (key != o.key) return key < o.key;
      if (tri != o.tri) return tri < o.tri;
      return edge < o.edge;
    }
  };
  std::vector<Record> records;
  records.reserve(3 * T);
  for (size_t t = 0; t < T; ++t) {
    const auto& tri = mesh.triangles[t];
    if (weldDegenerate(mesh, tri)) continue;
    for (uint32_t e = 0; e < 3; ++e) {
      uint32_t a = mesh.weldId[tri[e]], b = mesh.weldId[tri[(e + 1) % 3]];
      uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      records.push_back({key, uint32_t(t), e});
    }
  }
  std::sort(records.begin(), records.end());

  for (size_t i = 0; i < records.size();) {
    size_t j = i + 1;
    while (j < records.size() && records[j].key == records[i].key) ++j;
    if (j - i == 1) {
      ++adj.boundaryEdges;
    } else if (j - i == 2) {
      // Two triangles: neighbours, whatever their orientations (an inconsistently wound pair still
      // shares the edge; the normals decide whether it is smooth).
      const Record& r = records[i];
      const Record& s = records[i + 1];
      adj.neighbour[r.tri][r.edge] = int32_t(s.tri);
      adj.neighbourEdge[r.tri][r.edge] = int8_t(s.edge);
      adj.neighbour[s.tri][s.edge] = int32_t(r.tri);
      adj.neighbourEdge[s.tri][s.edge] = int8_t(r.edge);
    } else {
      // More than two: no pairing is better than another, so none is made.
      ++adj.nonManifoldEdges;
    }
    i = j;
  }
  return adj;
}

// The corner of `tri` at welded position `w` on its edge f (one of the edge's two endpoints).
int cornerOnEdgeAt(const Mesh& mesh, const std::array<uint32_t, 3>& tri, int f, uint32_t w) {
  return mesh.weldId[tri[f]] == w ? f : (f + 1) % 3;
}

bool differs(const glm::dvec3& a, const glm::dvec3& b) {
  return std::abs(a.x - b.x) > kSameNormalTolerance || std::abs(a.y - b.y) > kSameNormalTolerance ||
         std::abs(a.z - b.z) > kSameNormalTolerance;
}

// Union-find over triangle corners (3t + c), with path halving.
struct CornerSets {
  std::vector<uint32_t> parent;
  explicit CornerSets(size_t n) : parent(n) {
    for (size_t i = 0; i < n; ++i) parent[i] = uint32_t(i);
  }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    // The smaller index becomes the root, so a fan's root is its first corner in triangle order.
    if (a < b) parent[b] = a;
    else if (b < a) parent[a] = b;
  }
};

}  // namespace

MeshTopology buildTopology(const Mesh& mesh) {
  checkMesh(mesh, "buildTopology", true);
  const size_t T = mesh.triangles.size();
  Adjacency adj = weldedAdjacency(mesh);

  MeshTopology topo;
  topo.neighbour = std::move(adj.neighbour);
  topo.neighbourEdge = std::move(adj.neighbourEdge);
  topo.boundaryEdges = adj.boundaryEdges;
  topo.nonManifoldEdges = adj.nonManifoldEdges;
  topo.creaseSlot.resize(T);
  topo.neighbourVertex.resize(T);

  for (size_t t = 0; t < T; ++t) {
    const auto& tri = mesh.triangles[t];
    const glm::dvec3 p[3] = {mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]};
    glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    // Zero area up to rounding: |sin| of the angle at corner 0 below a few ulps.
    if (weldDegenerate(mesh, tri) || !(glm::length(glm::cross(e1, e2)) > 1e-14 * glm::length(e1) * glm::length(e2)))
      ++topo.degenerateTriangles;

    for (int s = 0; s < 6; ++s) {
      const int c = slotCorner(s), e = slotEdge(s);
      const uint32_t v = tri[c];
      const int32_t u = topo.neighbour[t][e];
      uint32_t w = v;
      if (u >= 0) {
        const auto& ut = mesh.triangles[size_t(u)];
        w = ut[cornerOnEdgeAt(mesh, ut, topo.neighbourEdge[t][e], mesh.weldId[v])];
      }
      topo.neighbourVertex[t][s] = w;
      topo.creaseSlot[t][s] = uint8_t(w != v && differs(mesh.normals[v], mesh.normals[w]));
    }
  }

  // An edge is a crease when either end is; counted once, from the side with the smaller (t, e).
  for (size_t t = 0; t < T; ++t)
    for (int e = 0; e < 3; ++e) {
      const int32_t u = topo.neighbour[t][e];
      if (u < 0) continue;
      const int f = topo.neighbourEdge[t][e];
      if (size_t(u) < t || (size_t(u) == t && f < e)) continue;
      if (topo.creaseSlot[t][2 * e + 1] || topo.creaseSlot[t][2 * ((e + 1) % 3)]) ++topo.creaseEdges;
    }
  return topo;
}

// Appends vertex v's texture coordinate and colour (where the mesh has them) for a copy of v.
namespace {
void copyCarriedAttributes(Mesh& mesh, uint32_t v) {
  if (!mesh.texcoords.empty()) mesh.texcoords.push_back(glm::dvec2(mesh.texcoords[v]));
  if (!mesh.colors.empty()) mesh.colors.push_back(glm::dvec4(mesh.colors[v]));
}
}  // namespace

void applyCreaseAngle(Mesh& mesh, double creaseAngleDeg) {
  // Normals from the file are the sharpness model itself (METHOD.md 3.1): never overridden.
  if (mesh.normalsFromFile) return;
  checkMesh(mesh, "applyCreaseAngle", false);
  const size_t T = mesh.triangles.size();
  const size_t n0 = mesh.positions.size();
  if (3 * T >= (size_t(1) << 32)) throw Error(ErrorKind::Internal, "applyCreaseAngle: too many triangles");
  mesh.normals.resize(n0, glm::dvec3(0, 0, 1));

  // Unit face normals and corner angles, by the same formula as computeVertexNormals, so that a vertex
  // that is not split keeps its normal bit for bit. A triangle of exactly zero area has no normal.
  std::vector<glm::dvec3> faceNormal(T, glm::dvec3(0.0));
  std::vector<uint8_t> flat(T, 0);
  std::vector<double> cornerAngle(3 * T, 0.0);
  for (size_t t = 0; t < T; ++t) {
    const auto& tri = mesh.triangles[t];
    const glm::dvec3 p[3] = {mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]};
    glm::dvec3 fn = glm::cross(p[1] - p[0], p[2] - p[0]);
    double len = glm::length(fn);
    if (!(len > 0) || !std::isfinite(len)) {
      flat[t] = 1;
      continue;
    }
    faceNormal[t] = fn / len;
    for (int c = 0; c < 3; ++c) {
      glm::dvec3 e1 = p[(c + 1) % 3] - p[c], e2 = p[(c + 2) % 3] - p[c];
      cornerAngle[3 * t + c] = std::atan2(glm::length(glm::cross(e1, e2)), glm::dot(e1, e2));
    }
  }

  // Dihedral angle per triangle edge; -1 where no fan crosses: boundaries, non-manifold edges and
  // triangles without a normal (0 as a crossing edge of the relative rule).
  Adjacency adj = weldedAdjacency(mesh);
  std::vector<double> dihedral(3 * T, -1.0);
  for (size_t t = 0; t < T; ++t) {
    if (flat[t]) continue;
    for (int e = 0; e < 3; ++e) {
      const int32_t u = adj.neighbour[t][e];
      if (u < 0 || flat[size_t(u)]) continue;
      const glm::dvec3 &a = faceNormal[t], &b = faceNormal[size_t(u)];
      dihedral[3 * t + e] = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * (180.0 / std::numbers::pi);
    }
  }
  const bool relative = creaseAngleDeg < 0;
  auto isCrease = [&](size_t t, int e) {
    const double angle = dihedral[3 * t + e];
    if (!relative) return angle > creaseAngleDeg;
    const size_t u = size_t(adj.neighbour[t][e]);
    const int ue = adj.neighbourEdge[t][e];
    const double crossing[4] = {std::max(0.0, dihedral[3 * t + (e + 1) % 3]), std::max(0.0, dihedral[3 * t + (e + 2) % 3]),
                                std::max(0.0, dihedral[3 * u + (ue + 1) % 3]), std::max(0.0, dihedral[3 * u + (ue + 2) % 3])};
    return autoCrease(angle, crossing);
  };

  // Smoothing fans: corners of one welded position joined across every smooth manifold edge. Creases,
  // boundaries, non-manifold edges and triangles without a normal end a fan.
  CornerSets fans(3 * T);
  for (size_t t = 0; t < T; ++t) {
    if (flat[t]) continue;
    for (int e = 0; e < 3; ++e) {
      const int32_t u = adj.neighbour[t][e];
      if (u < 0 || size_t(u) < t || flat[size_t(u)]) continue;
      if (isCrease(t, e)) continue;
      const auto& tri = mesh.triangles[t];
      const auto& ut = mesh.triangles[size_t(u)];
      for (int k : {e, (e + 1) % 3}) {
        int uc = cornerOnEdgeAt(mesh, ut, adj.neighbourEdge[t][e], mesh.weldId[tri[k]]);
        fans.unite(uint32_t(3 * t + k), uint32_t(3 * size_t(u) + uc));
      }
    }
  }

  // One angle-weighted normal per fan, summed in triangle order as computeVertexNormals does.
  std::unordered_map<uint32_t, glm::dvec3> fanSum;
  for (size_t t = 0; t < T; ++t) {
    if (flat[t]) continue;
    for (int c = 0; c < 3; ++c)
      fanSum.try_emplace(fans.find(uint32_t(3 * t + c)), 0.0).first->second += cornerAngle[3 * t + c] * faceNormal[t];
  }

  // Vertices: the first fan (in triangle order) that uses a vertex keeps it; every other fan using it
  // gets a copy appended (same position and weldId, and the same .bpt patch data). Copying per
  // (fan, original vertex) rather than merging keeps vertices that were already distinct (seams) apart.
  const bool hasPatchData = mesh.vertexPatch.size() == n0 && mesh.vertexUV.size() == n0;
  std::vector<int64_t> vertexFan(n0, -1);
  std::unordered_map<uint64_t, uint32_t> copies;
  for (size_t t = 0; t < T; ++t) {
    // A triangle with no normal keeps its vertices: it has no fan of its own to split them into.
    if (flat[t]) continue;
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = mesh.triangles[t][c];
      const uint32_t fan = fans.find(uint32_t(3 * t + c));
      if (vertexFan[v] < 0) vertexFan[v] = fan;
      if (vertexFan[v] == int64_t(fan)) continue;
      uint64_t key = (uint64_t(fan) << 32) | v;
      auto it = copies.find(key);
      if (it == copies.end()) {
        const uint32_t copy = uint32_t(mesh.positions.size());
        const glm::dvec3 position = mesh.positions[v], normal = mesh.normals[v];
        const uint32_t weld = mesh.weldId[v];
        mesh.positions.push_back(position);
        mesh.normals.push_back(normal);
        mesh.weldId.push_back(weld);
        copyCarriedAttributes(mesh, v);
        if (hasPatchData) {
          const uint32_t patch = mesh.vertexPatch[v];
          const glm::dvec2 uv = mesh.vertexUV[v];
          mesh.vertexPatch.push_back(patch);
          mesh.vertexUV.push_back(uv);
        }
        vertexFan.push_back(fan);
        it = copies.emplace(key, copy).first;
      }
      mesh.triangles[t][c] = it->second;
    }
  }

  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    if (vertexFan[v] < 0) continue;   // unused, or used only by triangles without a normal: unchanged
    const glm::dvec3& sum = fanSum.at(uint32_t(vertexFan[v]));
    double len = glm::length(sum);
    if (len > 0 && std::isfinite(len)) mesh.normals[v] = sum / len;
  }
}

}  // namespace sffd
