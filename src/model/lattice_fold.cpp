#include "model/lattice_fold.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "kernels/common/lattice_eval.h"

namespace sffd {

FoldCheck checkLatticeFold(const PackedLattice& P, size_t maxCoefficientVisits) {
  using Eval = LatticeEvaluator<double>;
  constexpr int K = Eval::kMax;
  FoldCheck r;
  const uint32_t deg[3] = {P.params.degree.x, P.params.degree.y, P.params.degree.z};
  const uint32_t nb[3] = {P.params.boxes.x, P.params.boxes.y, P.params.boxes.z};
  const uint32_t offs[3] = {P.params.break_offset.x, P.params.break_offset.y, P.params.break_offset.z};
  const size_t perBox = P.params.boxes.w;
  r.boxes = size_t(nb[0]) * nb[1] * nb[2];
  if (r.boxes == 0 || perBox == 0 || P.coeffs.size() < 4 * r.boxes * perBox) return r;
  for (int a = 0; a < 3; ++a)
    if (deg[a] < 1 || deg[a] >= uint32_t(K) || P.frame.size() < size_t(offs[a]) + nb[a] + 1) return r;

  // det(A) of the world -> parameter map (rows at SFFD_FRAME_AFFINE).
  glm::dmat3 A;
  for (int row = 0; row < 3; ++row)
    for (int c = 0; c < 3; ++c) A[c][row] = P.frame[SFFD_FRAME_AFFINE + 4 * row + c];
  const double detA = glm::determinant(A);
  if (!std::isfinite(detA) || detA == 0) return r;

  // Bernstein values and derivatives at s = 0, 1/2, 1 per axis.
  static const double kS[3] = {0.0, 0.5, 1.0};
  double b[3][3][K], db[3][3][K];
  for (int a = 0; a < 3; ++a)
    for (int s = 0; s < 3; ++s) Eval::bernstein(deg[a], kS[s], b[a][s], db[a][s]);

  const size_t visitsPerBox = 27 * perBox;
  size_t stride = 1;
  if (r.boxes * visitsPerBox > maxCoefficientVisits) stride = (r.boxes * visitsPerBox + maxCoefficientVisits - 1) / maxCoefficientVisits;

  const uint32_t nv = deg[1] + 1, nw = deg[2] + 1;
  r.minRatio = std::numeric_limits<double>::infinity();
  r.maxRatio = -std::numeric_limits<double>::infinity();
  for (size_t box = 0; box < r.boxes; box += stride) {
    const uint32_t bu = uint32_t(box / (size_t(nb[1]) * nb[2])), bv = uint32_t((box / nb[2]) % nb[1]), bw = uint32_t(box % nb[2]);
    const double h[3] = {P.frame[offs[0] + bu + 1] - P.frame[offs[0] + bu], P.frame[offs[1] + bv + 1] - P.frame[offs[1] + bv],
                         P.frame[offs[2] + bw + 1] - P.frame[offs[2] + bw]};
    const double* c0 = &P.coeffs[4 * box * perBox];
    ++r.boxesChecked;
    for (int su = 0; su < 3; ++su)
      for (int sv = 0; sv < 3; ++sv)
        for (int sw = 0; sw < 3; ++sw) {
          glm::dvec3 Ru(0.0), Rv(0.0), Rw(0.0);
          for (uint32_t i = 0; i <= deg[0]; ++i)
            for (uint32_t j = 0; j <= deg[1]; ++j)
              for (uint32_t k = 0; k <= deg[2]; ++k) {
                const double* c = c0 + 4 * ((size_t(i) * nv + j) * nw + k);
                const glm::dvec3 cp(c[0], c[1], c[2]);
                Ru += cp * (db[0][su][i] * b[1][sv][j] * b[2][sw][k]);
                Rv += cp * (b[0][su][i] * db[1][sv][j] * b[2][sw][k]);
                Rw += cp * (b[0][su][i] * b[1][sv][j] * db[2][sw][k]);
              }
          // d/dp = (1/h) d/ds on each axis; ratio = det J_R / det(A^-1) = det(A J_R): the product first,
          // parameters per parameter, so the cubes of lengths that det J_R and det A are stay in double's
          // range for a lattice of any size.
          const double ratio = glm::determinant(A * glm::dmat3(Ru / h[0], Rv / h[1], Rw / h[2]));
          ++r.samples;
          if (!std::isfinite(ratio) || std::abs(ratio) <= FoldCheck::kCollapse) ++r.degenerate;
          else if (ratio > 0) ++r.positive;
          else ++r.negative;
          if (std::isfinite(ratio)) {
            if (ratio < r.minRatio) {
              r.minRatio = ratio;
              r.worstAt = {P.frame[offs[0] + bu] + kS[su] * h[0], P.frame[offs[1] + bv] + kS[sv] * h[1],
                           P.frame[offs[2] + bw] + kS[sw] * h[2]};
            }
            r.maxRatio = std::max(r.maxRatio, ratio);
          }
        }
  }
  if (r.samples == 0 || !std::isfinite(r.minRatio)) r.minRatio = r.maxRatio = 0;
  return r;
}

std::string foldWarning(const FoldCheck& c, const std::string& name) {
  if (c.clean()) return "";
  char where[160];
  std::snprintf(where, sizeof where, "; worst at lattice parameter (%.6g, %.6g, %.6g), det J ratio %.3g", c.worstAt.x, c.worstAt.y,
                c.worstAt.z, c.minRatio);
  std::string what = c.mirrored()  ? "is mirrored (det J < 0 everywhere sampled): the output is turned inside out"
                     : c.folds()   ? "folds over (det J changes sign): the output may self-intersect and its normals flip there"
                                   : "collapses (det J = 0): the output is flattened there and its normals are undefined";
  std::string counts = " (" + std::to_string(c.negative) + " inverted and " + std::to_string(c.degenerate) + " collapsed of " +
                       std::to_string(c.samples) + " samples in " + std::to_string(c.boxesChecked) + " of " +
                       std::to_string(c.boxes) + " knot boxes" + where + ")";
  return "lattice " + name + " " + what + counts;
}

}  // namespace sffd
