#include "pipelines/patch_output.h"

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
  size_t operator()(const std::array<uint64_t, 6>& k) const {
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

Mesh weldPatchVertices(const PatchVertices& P) {
  Mesh m;
  m.normalsFromFile = true;
  const int nv = tessVertexCount(P.level);
  std::vector<uint32_t> local = tessTriangles(P.level);
  std::unordered_map<std::array<uint64_t, 6>, uint32_t, KeyHash> ids;
  std::unordered_map<std::array<uint64_t, 3>, uint32_t, KeyHash> welds;
  std::vector<uint32_t> map(nv);
  for (size_t p = 0; p < P.patchCount(); ++p) {
    for (int v = 0; v < nv; ++v) {
      size_t g = p * nv + v;
      std::array<uint64_t, 6> key;
      std::memcpy(key.data(), &P.position[3 * g], 24);
      std::memcpy(key.data() + 3, &P.normal[3 * g], 24);
      auto [it, fresh] = ids.emplace(key, uint32_t(m.positions.size()));
      if (fresh) {
        m.positions.push_back({P.position[3 * g], P.position[3 * g + 1], P.position[3 * g + 2]});
        m.normals.push_back({P.normal[3 * g], P.normal[3 * g + 1], P.normal[3 * g + 2]});
        std::array<uint64_t, 3> wk{key[0], key[1], key[2]};
        m.weldId.push_back(welds.emplace(wk, uint32_t(welds.size())).first->second);
      }
      map[v] = it->second;
    }
    for (size_t i = 0; i < local.size(); i += 3) {
      std::array<uint32_t, 3> t{map[local[i]], map[local[i + 1]], map[local[i + 2]]};
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;   // a collapsed corner of a degenerate patch
      m.triangles.push_back(t);
    }
  }
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
