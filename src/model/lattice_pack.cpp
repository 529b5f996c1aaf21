#include "model/lattice_pack.h"

namespace sffd {

PackedLattice packLattice(const Lattice& L) {
  LatticeBoxForm F = extractBoxForm(L);
  PackedLattice P;
  P.params.degree = {uint32_t(F.degree[0]), uint32_t(F.degree[1]), uint32_t(F.degree[2]),
                     L.outside == OutsideMode::Keep ? SFFD_OUTSIDE_KEEP : SFFD_OUTSIDE_EXTRAPOLATE};
  P.params.boxes = {uint32_t(F.boxes[0]), uint32_t(F.boxes[1]), uint32_t(F.boxes[2]), uint32_t(F.coeffsPerBox())};
  P.frame.assign(SFFD_FRAME_BREAKS, 0.0);
  glm::dmat3 cofA = cofactor(L.frameLinear);
  for (int r = 0; r < 3; ++r) {
    // glm is column-major: row r of M is (M[0][r], M[1][r], M[2][r]).
    for (int c = 0; c < 3; ++c) {
      P.frame[SFFD_FRAME_AFFINE + 4 * r + c] = L.frameLinear[c][r];
      P.frame[SFFD_FRAME_COF_AFFINE + 4 * r + c] = cofA[c][r];
    }
    P.frame[SFFD_FRAME_AFFINE + 4 * r + 3] = L.frameOffset[r];
  }
  uint32_t offs[3];
  for (int a = 0; a < 3; ++a) {
    offs[a] = uint32_t(P.frame.size());
    P.frame.insert(P.frame.end(), F.breaks[a].begin(), F.breaks[a].end());
  }
  P.params.break_offset = {offs[0], offs[1], offs[2], 0};
  P.coeffs.reserve(F.coeffs.size() * 4);
  for (const glm::dvec3& c : F.coeffs) P.coeffs.insert(P.coeffs.end(), {c.x, c.y, c.z, 0.0});
  return P;
}

namespace {
void putReals(const double* reals, size_t count, size_t firstReal, gpu::Vec4 (&block)[SFFD_INLINE_LATTICE_VEC4]) {
  for (size_t i = 0; i < count; ++i) {
    gpu::Vec4& q = block[(firstReal + i) / 4];
    const size_t c = (firstReal + i) % 4;
    (c == 0 ? q.x : c == 1 ? q.y : c == 2 ? q.z : q.w) = float(reals[i]);
  }
}
}  // namespace

uint32_t inlineLattice(const PackedLattice& lattice, bool f64, gpu::LatticeParams& params,
                       gpu::Vec4 (&block)[SFFD_INLINE_LATTICE_VEC4]) {
  params = lattice.params;
  params.break_offset.w = 0;
  const size_t frameVec4 = (lattice.frame.size() + 3) / 4, coeffVec4 = lattice.coeffs.size() / 4;
  if (f64 || frameVec4 == 0 || frameVec4 + coeffVec4 > SFFD_INLINE_LATTICE_VEC4) return 0;
  putReals(lattice.frame.data(), lattice.frame.size(), 0, block);
  putReals(lattice.coeffs.data(), lattice.coeffs.size(), 4 * frameVec4, block);
  params.break_offset.w = uint32_t(frameVec4);
  return uint32_t(frameVec4 + coeffVec4);
}

uint32_t inlineReals(const double* reals, size_t count, uint32_t first, gpu::Vec4 (&block)[SFFD_INLINE_LATTICE_VEC4]) {
  if (first == 0 || count == 0 || first + (count + 3) / 4 > SFFD_INLINE_LATTICE_VEC4) return 0;
  putReals(reals, count, 4 * size_t(first), block);
  return first;
}

gpu::DeformParams deformParamsFor(const PackedLattice& lattice, bool f64, const std::vector<double>* fit) {
  gpu::DeformParams d{};
  d.sections.y = uint32_t(lattice.frame.size());   // the fit table after the frame (deformFrameRange)
  const uint32_t fitFirst = inlineLattice(lattice, f64, d.lattice, d.inline_lattice);
  if (fit) d.sections.x = inlineReals(fit->data(), fit->size(), fitFirst, d.inline_lattice);
  return d;
}

std::vector<double> deformFrameRange(const PackedLattice& lattice, const std::vector<double>& fit) {
  std::vector<double> r = lattice.frame;
  r.insert(r.end(), fit.begin(), fit.end());
  return r;
}

}  // namespace sffd
