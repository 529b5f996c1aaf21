// Lattices the kernel and analysis tests build around a mesh: its bounding box as an identity lattice,
// and the same with its control points moved at random (seeded, so every run deforms alike).
#pragma once
#include <array>
#include <random>

#include "model/lattice.h"
#include "model/mesh.h"

namespace sffd::test {

// The identity lattice of `counts` control points and `degree` on the mesh's bounding box grown by `margin`.
inline Lattice boxLattice(const Mesh& m, std::array<int, 3> counts, std::array<int, 3> degree, double margin = 0.0) {
  glm::dvec3 lo = m.positions[0], hi = lo;
  for (const auto& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  return makeIdentityLattice(lo - margin, hi + margin, counts, degree);
}

// Moves every control point by up to `amount` on each axis, uniformly at random from `seed`.
inline void perturb(Lattice& L, double amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (auto& p : L.controlPoints) p += glm::dvec3(u(rng), u(rng), u(rng));
}

}  // namespace sffd::test
