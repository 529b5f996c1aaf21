// What the lattice tests share: a lattice evaluated as the kernels evaluate it (its packed per-knot-box
// form, in double), and random lattices with optionally non-uniform knots.
#pragma once
#include <random>

#include "kernels/common/lattice_eval.h"
#include "model/lattice.h"
#include "model/lattice_pack.h"

namespace sffd::test {

struct Evaluated {
  PackedLattice packed;
  std::vector<double> frame, coeffs;
  LatticeEvaluator<double> eval;
  explicit Evaluated(const Lattice& L)
      : packed(packLattice(L)), frame(packed.frame), coeffs(packed.coeffs), eval(packed.params, frame, coeffs) {}
  glm::dvec3 at(glm::dvec3 x) const {
    const RVec3<double> v = eval.evaluate(RVec3<double>{x.x, x.y, x.z}).value;
    return {v.x, v.y, v.z};
  }
};

// Over the box [-1, 1.5] x [-2, 1] x [-0.5, 0.5], control points moved by up to 0.2 on each axis;
// non-uniform: interior knots moved by up to 0.12 of their span.
inline Lattice randomLattice(std::mt19937& rng, std::array<int, 3> degree, std::array<int, 3> counts, bool nonUniform) {
  Lattice L = makeIdentityLattice({-1, -2, -0.5}, {1.5, 1, 0.5}, counts, degree);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  if (nonUniform)
    for (int a = 0; a < 3; ++a) {
      auto& k = L.knots[a];
      for (int i = degree[a] + 1; i < counts[a]; ++i) k[i] = k[i] + 0.3 * (k[i + 1] - k[i]) * (u(rng) + 0.2);
    }
  for (auto& p : L.controlPoints) p += glm::dvec3(u(rng), u(rng), u(rng));
  return L;
}

}  // namespace sffd::test
