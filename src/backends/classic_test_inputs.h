// Inputs of the classic_ffd kernel built by hand for the backend tests: a lattice of one knot box whose
// map is known, and seeded points and normals inside and outside it.
#pragma once
#include <cmath>
#include <random>
#include <vector>

#include "kernels/common/shader_layout.h"

namespace sffd::testing {

// One knot box [0,1]^3 of degree 1, identity frame; coefficient (p*2+q)*2+r is the corner (p,q,r).
// `moved` displaces two corners so that the map is not the identity.
template <class Real>
struct HandLattice {
  gpu::LatticeParams params;
  std::vector<Real> frame, coeffs;
  explicit HandLattice(bool moved = false) {
    params.degree = {1, 1, 1, SFFD_OUTSIDE_EXTRAPOLATE};
    params.boxes = {1, 1, 1, 8};
    params.break_offset = {SFFD_FRAME_BREAKS, SFFD_FRAME_BREAKS + 2, SFFD_FRAME_BREAKS + 4, 0};
    frame = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0,    // affine rows
             1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0,    // cof(A) rows
             0, 1, 0, 1, 0, 1};                      // breaks u, v, w
    for (int p = 0; p < 2; ++p)
      for (int q = 0; q < 2; ++q)
        for (int r = 0; r < 2; ++r) coeffs.insert(coeffs.end(), {Real(p), Real(q), Real(r), Real(0)});
    if (moved) {
      coeffs[4 * 7 + 0] = Real(1.3), coeffs[4 * 7 + 1] = Real(0.8), coeffs[4 * 7 + 2] = Real(1.17);
      coeffs[4 * 2 + 1] = Real(1.25);
    }
  }
};

// Points (w = 1) and unit normals (w = 0) as real4: `inside` of them in [0,1]^3, the rest outside on x.
template <class Real>
void makeVertices(size_t n, size_t inside, std::vector<Real>& pos, std::vector<Real>& nrm, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> in(0.0, 1.0), out(-0.5, 1.5), dir(-1.0, 1.0);
  pos.assign(4 * n, 0);
  nrm.assign(4 * n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) pos[4 * i + k] = Real(i < inside ? in(rng) : out(rng));
    if (i >= inside) pos[4 * i] = Real(1.25 + 0.25 * in(rng));
    pos[4 * i + 3] = 1;
    double v[3], len = 0;
    do {
      for (double& c : v) c = dir(rng);
      len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    } while (len < 0.1);
    for (int k = 0; k < 3; ++k) nrm[4 * i + k] = Real(v[k] / len);
  }
}

}  // namespace sffd::testing
