// shaders/common/layout.h: the one place where buffer bindings, work-group size and
// parameter-block layouts shared by the GLSL kernels and the C++ host are declared.
// This file is valid GLSL (after shaders/common/prelude.glsl) and valid C++
// (after src/core/shader_layout.h), so the two sides cannot drift apart.
//
// Real-valued data (positions, lattice) lives in storage buffers of `real`, which is float or
// double per kernel variant (SFFD_F64); parameter blocks hold only integers.
//
// Rules that keep std140 (GLSL) and C++ layouts identical: parameter blocks hold only
// vec4 / uvec4 / ivec4 members and arrays of them (16-byte stride in both).
// Storage buffers hold vec4 or float/uint arrays, never vec3 (std430 pads vec3 to 16 bytes).
#ifndef SFFD_LAYOUT_H
#define SFFD_LAYOUT_H

// Work-group size of every 1-D kernel.
#define SFFD_LOCAL_SIZE 64
// Largest work-group count per dimension guaranteed by the API (and the limit on llvmpipe/lavapipe).
#define SFFD_MAX_GROUPS_X 65535

// Binding 0 of every kernel is its parameter block (a uniform buffer); storage buffers use 1..SFFD_MAX_STORAGE_BINDINGS.
// Vulkan shares one binding namespace between uniform and storage buffers, so the numbers never overlap.
#define SFFD_BINDING_PARAMS 0
#define SFFD_MAX_STORAGE_BINDINGS 12

// Highest B-spline degree per axis supported by the kernels.
#define SFFD_MAX_DEGREE 5

// ---- lattice (shared by every kernel that evaluates the B-spline volume) ----
#define SFFD_BINDING_LATTICE_COEFFS 1   // per-knot-box Bezier control points: real4 each (w unused)
#define SFFD_BINDING_LATTICE_FRAME 2    // reals: the affine frame, then the distinct knot values

// Offsets (in reals) inside the lattice frame buffer.
#define SFFD_FRAME_AFFINE 0        // 12: rows of the 3x4 map world point -> lattice parameter
#define SFFD_FRAME_COF_AFFINE 12   // 12: rows of cof(A) (A = the 3x3 part), 4th of each row unused
#define SFFD_FRAME_BREAKS 24       // distinct knot values of u, then v, then w

// outside_mode values: what happens to a point outside the lattice box.
#define SFFD_OUTSIDE_EXTRAPOLATE 0u   // evaluate the nearest knot box's polynomial (continuous)
#define SFFD_OUTSIDE_KEEP 1u          // leave the point and its normal unmoved, as PyGeM does

// The lattice part of every parameter block.
SFFD_STRUCT_BEGIN(LatticeParams)
  SFFD_UVEC4 degree;         // xyz: degree per axis (1..SFFD_MAX_DEGREE); w: outside_mode
  SFFD_UVEC4 boxes;          // xyz: knot boxes per axis; w: coefficients per box
  SFFD_UVEC4 break_offset;   // xyz: first break of each axis in the frame buffer
SFFD_STRUCT_END(LatticeParams)

// ---- kernel classic_ffd: one thread per vertex, deforms the position and normal ----
#define SFFD_BINDING_CLASSIC_POS_IN 3    // real4 per vertex (w ignored)
#define SFFD_BINDING_CLASSIC_NRM_IN 4    // real4 per vertex (w ignored)
#define SFFD_BINDING_CLASSIC_POS_OUT 5   // real4 per vertex (w = 1 inside the lattice box, 0 outside)
#define SFFD_BINDING_CLASSIC_NRM_OUT 6   // real4 per vertex (unit normal, w = 0)

SFFD_STRUCT_BEGIN(ClassicParams)
  SFFD_STRUCT_MEMBER(LatticeParams, lattice)
  SFFD_UVEC4 range;          // x: first vertex of this chunk (relative to the bound ranges), y: vertex count
SFFD_STRUCT_END(ClassicParams)

// ---- kernel pn_triangles: one thread per original triangle (ALGORITHM.md 3.2) ----
// Mesh buffers shared by the pre-compute kernels.
#define SFFD_BINDING_MESH_POSITIONS 3      // real4 per vertex (w unused)
#define SFFD_BINDING_MESH_NORMALS 4        // real4 per vertex, unit (w unused)
#define SFFD_BINDING_MESH_TRIANGLES 5      // 2 uvec4 per triangle: vertex ids (w unused), weld ids (w unused)
#define SFFD_BINDING_MESH_SLOT_NORMALS 6   // 12 real4 per triangle: per corner slot, the first then the second
                                           // normal of the slot (w of the first: 1 crease, 0 smooth)
#define SFFD_BINDING_PN_OUT 7              // SFFD_PN_STRIDE real4 per triangle
#define SFFD_MESH_TRIANGLE_STRIDE 2
#define SFFD_SLOT_NORMAL_STRIDE 12
// PN record: the 10 cubic geometry control points (linear index order 300,210,201,120,111,102,030,021,012,003)
// then the 6 quadratic normal control points (200,110,101,020,011,002).
#define SFFD_PN_STRIDE 16
#define SFFD_PN_NORMALS 10

SFFD_STRUCT_BEGIN(PnParams)
  SFFD_UVEC4 range;   // x: first triangle, y: triangle count
SFFD_STRUCT_END(PnParams)

#endif
