// The FFD lattice: a trivariate B-spline volume of any degree 1..5 per axis (METHOD.md 1).
// Plain data: control points in world space, knot vectors in lattice-parameter space, and an affine
// frame mapping world points to parameters (the identity for native lattices, PyGeM's rotated box
// for .prm lattices).
#pragma once
#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace sffd {

enum class OutsideMode {
  Extrapolate,   // points outside the box follow the nearest knot box's polynomial (continuous)
  Keep,          // points outside the box are left unmoved (PyGeM)
};

struct Lattice {
  std::array<int, 3> degree{2, 2, 2};
  std::array<int, 3> counts{5, 5, 5};
  // Full knot vectors, counts[a] + degree[a] + 1 non-decreasing values each, in parameter space.
  std::array<std::vector<double>, 3> knots;
  // counts[0]*counts[1]*counts[2] points, index (i*counts[1] + j)*counts[2] + k, world coordinates.
  std::vector<glm::dvec3> controlPoints;
  // World -> parameter frame: p = frameLinear * x + frameOffset.
  glm::dmat3 frameLinear{1.0};
  glm::dvec3 frameOffset{0.0};
  OutsideMode outside = OutsideMode::Extrapolate;

  size_t pointCount() const { return size_t(counts[0]) * counts[1] * counts[2]; }
  size_t index(int i, int j, int k) const { return (size_t(i) * counts[1] + j) * counts[2] + k; }
  // Parameter-space domain of axis a: [knots[degree], knots[counts]].
  double domainLo(int a) const { return knots[a][degree[a]]; }
  double domainHi(int a) const { return knots[a][counts[a]]; }
};

// Clamped uniform knot vector over [lo, hi]: (degree+1) copies of each end, uniform interior knots.
std::vector<double> clampedUniformKnots(int count, int degree, double lo, double hi);

// Checks degrees (1..5), counts > degree, knot vector sizes and monotonicity, a non-empty domain,
// finite control points and an invertible frame. Throws an input Error naming `source`.
void validateLattice(const Lattice& lattice, const std::string& source);

// Same degrees, counts, knots, frame and outside rule (only the control points may differ): what a
// deformation prepared for one lattice may reuse for the other.
bool sameLatticeStructure(const Lattice& a, const Lattice& b);

// Greville abscissae of one axis: xi_i = (u_{i+1} + ... + u_{i+n}) / n.
std::vector<double> grevilleAbscissae(const std::vector<double>& knots, int degree);

// Sets every control point to the world position of its Greville parameter: the identity map.
void setIdentityControlPoints(Lattice& lattice);

// An axis-aligned lattice over [lo, hi] with clamped uniform knots and identity control points.
Lattice makeIdentityLattice(glm::dvec3 lo, glm::dvec3 hi, std::array<int, 3> counts, std::array<int, 3> degree);

// Per-knot-box Bezier form of the volume (Boehm knot insertion): what the kernels evaluate.
struct LatticeBoxForm {
  std::array<int, 3> degree{};
  std::array<std::vector<double>, 3> breaks;   // distinct knot values spanning the domain, boxes+1 each
  std::array<int, 3> boxes{};
  std::vector<glm::dvec3> coeffs;              // per box (nu+1)(nv+1)(nw+1), box (bu*Bv+bv)*Bw+bw, (p*(nv+1)+q)*(nw+1)+r
  size_t coeffsPerBox() const { return size_t(degree[0] + 1) * (degree[1] + 1) * (degree[2] + 1); }
};
LatticeBoxForm extractBoxForm(const Lattice& lattice);

// cof(M) = det(M) M^{-T}: maps normals through a linear map keeping orientation.
glm::dmat3 cofactor(const glm::dmat3& m);

}  // namespace sffd
