#include "pipelines/patch_output.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <unordered_map>

namespace sffd {

int tessVertexCount(int level) { return (level + 1) * (level + 2) / 2; }
int tessTriangleCount(int level) { return level * level; }

std::vector<uint32_t> tessTriangles(int L) {
  std::vector<uint32_t> t;
  auto idx = [](int r, int c) { return uint32_t(r * (r + 1) / 2 + c); };
  for (int r = 0; r < L; ++r)
    for (int c = 0; c <= r; ++c) {
      t.insert(t.end(), {idx(r, c), idx(r + 1, c), idx(r + 1, c + 1)});
      if (c < r) t.insert(t.end(), {idx(r, c), idx(r + 1, c + 1), idx(r, c + 1)});
    }
  return t;
}

namespace {
struct KeyHash {
  size_t operator()(const std::array<uint64_t, 6 + kCarriedKeyWords>& k) const {
    size_t h = 1469598103934665603ull;
    for (uint64_t v : k) h = (h ^ v) * 1099511628211ull;
    return h;
  }
  size_t operator()(const std::array<uint64_t, 3>& k) const {
    size_t h = 1469598103934665603ull;
    for (uint64_t v : k) h = (h ^ v) * 1099511628211ull;
    return h;
  }
};
}  // namespace

namespace {
// `values` (N doubles per vertex) at barycentric `lam` in triangle `t`: corners in weldId order, zero
// weights skipped (carryAttributes).
template <int N>
void interpolate(const std::vector<glm::vec<N, double>>& values, const std::array<uint32_t, 3>& t, const uint32_t* weld,
                 const double* lam, double* out) {
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int a, int b) { return weld[t[a]] < weld[t[b]]; });
  glm::vec<N, double> r(0.0);
  for (int c : order)
    if (lam[c] != 0.0) r += lam[c] * values[t[c]];
  for (int i = 0; i < N; ++i) out[i] = r[i];
}
}  // namespace

void carryAttributes(PatchVertices& P, const Mesh& input) {
  const size_t nv = size_t(tessVertexCount(P.level));
  const bool uv = !input.texcoords.empty(), rgba = !input.colors.empty();
  P.texcoord.assign(uv ? 2 * P.vertexCount() : 0, 0.0);
  P.color.assign(rgba ? 4 * P.vertexCount() : 0, 0.0);
  for (size_t g = 0; (uv || rgba) && g < P.vertexCount(); ++g) {
    const auto& t = input.triangles[P.parent[g / nv]];
    if (uv) interpolate(input.texcoords, t, input.weldId.data(), &P.lamParent[3 * g], &P.texcoord[2 * g]);
    if (rgba) interpolate(input.colors, t, input.weldId.data(), &P.lamParent[3 * g], &P.color[4 * g]);
  }
  auto perPatch = [&](const std::vector<uint32_t>& perTriangle, std::vector<uint32_t>& out) {
    out.clear();
    if (!perTriangle.empty())
      for (uint32_t parent : P.parent) out.push_back(perTriangle[parent]);
  };
  perPatch(input.triangleMaterial, P.material);
  perPatch(input.triangleGroup, P.group);
  P.materials = input.materials;
  P.groups = input.groups;
  P.materialLibraries = input.materialLibraries;
}

void carriedKey(const PatchVertices& P, size_t g, uint64_t* key) {
  std::fill(key, key + kCarriedKeyWords, 0);
  if (!P.texcoord.empty()) std::memcpy(key, &P.texcoord[2 * g], 16);
  if (!P.color.empty()) std::memcpy(key + 2, &P.color[4 * g], 32);
}

Mesh weldPatchVertices(const PatchVertices& P) {
  Mesh m;
  m.normalsFromFile = true;
  const int nv = tessVertexCount(P.level);
  std::vector<uint32_t> local = tessTriangles(P.level);
  std::unordered_map<std::array<uint64_t, 6 + kCarriedKeyWords>, uint32_t, KeyHash> ids;
  std::unordered_map<std::array<uint64_t, 3>, uint32_t, KeyHash> welds;
  std::vector<uint32_t> map(nv);
  for (size_t p = 0; p < P.patchCount(); ++p) {
    for (int v = 0; v < nv; ++v) {
      size_t g = p * nv + v;
      std::array<uint64_t, 6 + kCarriedKeyWords> key;
      std::memcpy(key.data(), &P.position[3 * g], 24);
      std::memcpy(key.data() + 3, &P.normal[3 * g], 24);
      carriedKey(P, g, key.data() + 6);
      auto [it, fresh] = ids.emplace(key, uint32_t(m.positions.size()));
      if (fresh) {
        m.positions.push_back({P.position[3 * g], P.position[3 * g + 1], P.position[3 * g + 2]});
        m.normals.push_back({P.normal[3 * g], P.normal[3 * g + 1], P.normal[3 * g + 2]});
        if (!P.texcoord.empty()) m.texcoords.push_back({P.texcoord[2 * g], P.texcoord[2 * g + 1]});
        if (!P.color.empty()) m.colors.push_back({P.color[4 * g], P.color[4 * g + 1], P.color[4 * g + 2], P.color[4 * g + 3]});
        std::array<uint64_t, 3> wk{key[0], key[1], key[2]};
        m.weldId.push_back(welds.emplace(wk, uint32_t(welds.size())).first->second);
      }
      map[v] = it->second;
    }
    for (size_t i = 0; i < local.size(); i += 3) {
      std::array<uint32_t, 3> t{map[local[i]], map[local[i + 1]], map[local[i + 2]]};
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;   // a collapsed corner of a degenerate patch
      m.triangles.push_back(t);
      if (!P.material.empty()) m.triangleMaterial.push_back(P.material[p]);
      if (!P.group.empty()) m.triangleGroup.push_back(P.group[p]);
    }
  }
  m.materials = P.materials;
  m.groups = P.groups;
  m.materialLibraries = P.materialLibraries;
  return m;
}

Mesh unweldedPatchMesh(const PatchVertices& pv) {
  Mesh m;
  const size_t nv = size_t(tessVertexCount(pv.level));
  std::vector<uint32_t> local = tessTriangles(pv.level);
  m.positions.reserve(pv.vertexCount());
  m.normals.reserve(pv.vertexCount());
  for (size_t v = 0; v < pv.vertexCount(); ++v) {
    m.positions.push_back({pv.position[3 * v], pv.position[3 * v + 1], pv.position[3 * v + 2]});
    m.normals.push_back({pv.normal[3 * v], pv.normal[3 * v + 1], pv.normal[3 * v + 2]});
    m.weldId.push_back(uint32_t(v));
  }
  for (size_t p = 0; p < pv.patchCount(); ++p)
    for (size_t i = 0; i < local.size(); i += 3)
      m.triangles.push_back({uint32_t(p * nv + local[i]), uint32_t(p * nv + local[i + 1]), uint32_t(p * nv + local[i + 2])});
  return m;
}

}  // namespace sffd
