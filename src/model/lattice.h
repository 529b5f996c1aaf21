// Lattice internals: the per-knot-box Bezier form the kernels evaluate, and helpers. The Lattice
// type itself is public (<sffd/lattice.h>).
#pragma once
#include <string>

#include <sffd/lattice.h>

namespace sffd {

// validateLattice without the control points (their count and values): what a lattice whose control
// points are about to be set (setIdentityControlPoints) must hold.
void validateLatticeStructure(const Lattice& lattice, const std::string& source);

// Greville abscissae of one axis: xi_i = (u_{i+1} + ... + u_{i+n}) / n.
std::vector<double> grevilleAbscissae(const std::vector<double>& knots, int degree);

// Per-knot-box Bezier form of the volume (Boehm knot insertion): what the kernels evaluate.
struct LatticeBoxForm {
  std::array<int, 3> degree{};
  std::array<std::vector<double>, 3> breaks;   // distinct knot values spanning the domain, boxes+1 each
  std::array<int, 3> boxes{};
  std::vector<glm::dvec3> coeffs;              // per box (nu+1)(nv+1)(nw+1), box (bu*Bv+bv)*Bw+bw, (p*(nv+1)+q)*(nw+1)+r
  size_t coeffsPerBox() const { return size_t(degree[0] + 1) * (degree[1] + 1) * (degree[2] + 1); }
};
LatticeBoxForm extractBoxForm(const Lattice& lattice);

// Knot insertion (Boehm) on a control polygon of vectors of any length (a lattice's control points
// along one axis, or unit vectors, whose result is the insertion's matrix): inserts t once into the
// knot vector U of degree p and updates P.
void insertKnot(std::vector<double>& U, std::vector<std::vector<double>>& P, int p, double t);

// cof(M) = det(M) M^{-T}: maps normals through a linear map keeping orientation.
glm::dmat3 cofactor(const glm::dmat3& m);

}  // namespace sffd
