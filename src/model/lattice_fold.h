// Fold-over check of a lattice: does the deformation turn space inside out somewhere?
//
// The map of a point is x -> R(A x + b): the affine frame, then the B-spline volume R. It folds where
// det J_R changes sign, and collapses where det J_R = 0. The check samples det J_R exactly (from the
// per-knot-box Bezier form the kernels evaluate, docs/ROBUSTNESS.md) at the 8 corners, the 6 face
// centres, the 12 edge midpoints and the centre of every knot box (a 3x3x3 grid in box-local
// coordinates), each box evaluated from its own polynomial, so that C0 lattices (degree 1, repeated
// knots) are seen from both sides of a break. det J_R is compared with det(A^-1), the identity
// lattice's constant, so that a frame of either handedness reads as positive when undeformed.
//
// It is a sampling check: cheap (27 evaluations a knot box, O(coefficients)), exact where it
// samples, and blind to a fold that starts and ends strictly between samples. Very large lattices
// are sampled on a subset of their knot boxes (an evenly spaced stride) so that the check stays below
// about 5e7 coefficient visits; FoldCheck says how many boxes were seen.
#pragma once
#include <cstddef>
#include <string>

#include <glm/glm.hpp>

#include "model/lattice_pack.h"

namespace sffd {

struct FoldCheck {
  size_t boxes = 0;          // knot boxes of the lattice
  size_t boxesChecked = 0;   // knot boxes sampled
  size_t samples = 0;        // det J evaluations
  size_t positive = 0;       // samples with the identity's orientation
  size_t negative = 0;       // samples turned inside out
  size_t degenerate = 0;     // samples where the volume collapses (|ratio| <= kCollapse)
  double minRatio = 1;       // smallest det J_R / det(A^-1) seen (1 everywhere for the identity)
  double maxRatio = 1;       // largest
  glm::dvec3 worstAt{0.0};   // lattice parameter of the sample with minRatio (parameter space)

  static constexpr double kCollapse = 1e-9;

  bool folds() const { return negative > 0 && (positive > 0 || degenerate > 0); }
  bool mirrored() const { return negative > 0 && positive == 0 && degenerate == 0; }
  bool collapses() const { return degenerate > 0; }
  bool clean() const { return negative == 0 && degenerate == 0; }
};

FoldCheck checkLatticeFold(const PackedLattice& lattice, size_t maxCoefficientVisits = 50'000'000);

// One line for "sffd: warning: ..." (without that prefix), empty when the check is clean.
std::string foldWarning(const FoldCheck& check, const std::string& latticeName);

}  // namespace sffd
