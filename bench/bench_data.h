// Shared inputs of the benchmarks: the models of the test data (tests/data), normalised the
// way `sffd --normalize` does (centred, largest half-extent 1/1.1), and a deformed lattice around
// them. Loaded once per process and cached, so file parsing never shows up in a timed loop.
#pragma once
#include <algorithm>
#include <array>
#include <map>
#include <string>

#include "model/lattice.h"
#include "io/lattice_io.h"
#include "model/mesh.h"

namespace sffd::bench {

inline const std::string kDataDir = std::string(SFFD_TEST_DATA) + "/";

inline void meshBox(const Mesh& m, glm::dvec3& lo, glm::dvec3& hi) {
  lo = glm::dvec3(1e300), hi = glm::dvec3(-1e300);
  for (const auto& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
}

// Centred, largest half-extent `scale` (the idea of apps/sffd/job.cpp normalizeMesh).
inline void normalize(Mesh& m, double scale) {
  glm::dvec3 lo, hi;
  meshBox(m, lo, hi);
  glm::dvec3 c = 0.5 * (lo + hi);
  double half = 0.5 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  double f = half > 0 ? scale / half : 1.0;
  for (auto& p : m.positions) p = (p - c) * f;
  for (auto& patch : m.patches)
    for (auto& p : patch.points) p = (p - c) * f;
}

// "teapot.bpt" (teapot, 36 Bezier patches at the default 10x10 grid = 7200 triangles) or an .obj name.
inline const Mesh& model(const std::string& file) {
  static std::map<std::string, Mesh> cache;
  auto it = cache.find(file);
  if (it == cache.end()) {
    Mesh m = readMesh(kDataDir + file);
    normalize(m, 1.0 / 1.1);
    it = cache.emplace(file, std::move(m)).first;
  }
  return it->second;
}

// A counts^3 lattice of the given degree over the mesh box (padded 1%), twisted: every control
// point moves, so no evaluation is trivially the identity.
inline Lattice deformedLattice(const Mesh& m, int counts, int degree, double twist = 0.5) {
  glm::dvec3 lo, hi;
  meshBox(m, lo, hi);
  glm::dvec3 pad = 0.01 * (hi - lo);
  Lattice L = makeIdentityLattice(lo - pad, hi + pad, {counts, counts, counts}, {degree, degree, degree});
  applyLatticePreset(L, "twist", twist);
  return L;
}

}  // namespace sffd::bench
