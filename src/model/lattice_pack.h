// The lattice as the kernels read it (kernels/common/lattice_eval.glsl): the parameter block, the frame
// buffer (affine frame, cof(A), knot breaks) and the per-box Bezier coefficients, kept in double
// and converted to the kernel's `real` type on upload.
#pragma once
#include <vector>

#include "model/lattice.h"
#include "kernels/common/shader_layout.h"

namespace sffd {

struct PackedLattice {
  gpu::LatticeParams params;
  std::vector<double> frame;    // SFFD_FRAME_* layout
  std::vector<double> coeffs;   // 4 per coefficient (x, y, z, 0)
};

PackedLattice packLattice(const Lattice& lattice);

// A parameter block's inline_lattice (layout.h, DeformParams and AccurateParams): in the float variants
// the lattice's frame reals, four to a vec4, then its coefficients, where they fit; `params` is the
// block's lattice part, its break_offset.w set to the coefficients' first vec4 (0: they are not there,
// the kernels read the lattice storage buffers). Returns the first vec4 after them (0: not inline).
uint32_t inlineLattice(const PackedLattice& lattice, bool f64, gpu::LatticeParams& params,
                       gpu::Vec4 (&block)[SFFD_INLINE_LATTICE_VEC4]);
// Appends `count` reals at vec4 `first` of an inline_lattice where they fit: returns where they begin
// (`first`), 0 where they do not fit or `first` is 0 (the lattice is not there either).
uint32_t inlineReals(const double* reals, size_t count, uint32_t first, gpu::Vec4 (&block)[SFFD_INLINE_LATTICE_VEC4]);

// The deform kernels' parameter block for a lattice: its LatticeParams, and in the float variants
// the lattice itself inline when it fits (layout.h, DeformParams), else break_offset.w = 0 and the
// kernels read the lattice storage buffers.
// With `fit`, the fit table follows the lattice there when both fit (sections.x). sections.y names
// where the fit table begins in the deform kernels' lattice frame range, deformFrameRange.
gpu::DeformParams deformParamsFor(const PackedLattice& lattice, bool f64, const std::vector<double>* fit = nullptr);
// The deform kernels' lattice frame range (SFFD_BINDING_LATTICE_FRAME): the frame, then the fit table.
std::vector<double> deformFrameRange(const PackedLattice& lattice, const std::vector<double>& fit);

template <class Real>
std::vector<Real> convertReals(const std::vector<double>& v) {
  return std::vector<Real>(v.begin(), v.end());
}

}  // namespace sffd
