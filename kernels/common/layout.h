// kernels/common/layout.h: the one place where buffer bindings, work-group size and
// parameter-block layouts shared by the GLSL kernels and the C++ host are declared.
// This file is valid GLSL (after kernels/common/prelude.glsl) and valid C++
// (after kernels/common/shader_layout.h), so the two sides cannot drift apart.
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
// The smallest squared length a vector has to have for snormalize to divide it by its length (prelude.glsl,
// rvec.h): the smallest normal float, in every precision (a float literal in both languages). Shorter ones
// (zero: a collinear triangle between opposite corner normals) are left as they are, not made NaN.
#define SFFD_MIN_DIRECTION_LENGTH2 1.17549435e-38f
// Largest work-group count per dimension guaranteed by the API (and the limit on llvmpipe/lavapipe).
#define SFFD_MAX_GROUPS_X 65535

// Binding 0 of every kernel is its parameter block (a uniform buffer); storage buffers use slots
// 1..SFFD_MAX_STORAGE_BINDINGS. Vulkan shares one binding namespace between uniform and storage
// buffers, so the numbers never overlap. OpenGL ES counts storage bindings from 0 in a namespace of
// their own, of which ES 3.1 guarantees only 4: there (GL_ES, the kernels' ES form) slot s is binding
// s - 1, and the gles backend binds it there. A table, since ES layout qualifiers take only literals
// and its preprocessor has no token pasting; the host (C++) always sees the slot numbers.
#define SFFD_BINDING_PARAMS 0
#define SFFD_MAX_STORAGE_BINDINGS 12
#if defined(GL_ES)
#define SFFD_SLOT_1 0
#define SFFD_SLOT_2 1
#define SFFD_SLOT_3 2
#define SFFD_SLOT_4 3
#define SFFD_SLOT_5 4
#define SFFD_SLOT_6 5
#define SFFD_SLOT_7 6
#define SFFD_SLOT_8 7
#define SFFD_SLOT_9 8
#define SFFD_SLOT_10 9
#define SFFD_SLOT_11 10
#else
#define SFFD_SLOT_1 1
#define SFFD_SLOT_2 2
#define SFFD_SLOT_3 3
#define SFFD_SLOT_4 4
#define SFFD_SLOT_5 5
#define SFFD_SLOT_6 6
#define SFFD_SLOT_7 7
#define SFFD_SLOT_8 8
#define SFFD_SLOT_9 9
#define SFFD_SLOT_10 10
#define SFFD_SLOT_11 11
#endif

// Highest B-spline degree per axis supported by the kernels.
#define SFFD_MAX_DEGREE 5

// ---- lattice (shared by every kernel that evaluates the B-spline volume) ----
#define SFFD_BINDING_LATTICE_COEFFS SFFD_SLOT_1   // per-knot-box Bezier control points: real4 each (w unused)
#define SFFD_BINDING_LATTICE_FRAME SFFD_SLOT_2    // reals: the affine frame, then the distinct knot values

// Offsets (in reals) inside the lattice frame buffer.
#define SFFD_FRAME_AFFINE 0u        // 12: rows of the 3x4 map world point -> lattice parameter
#define SFFD_FRAME_COF_AFFINE 12u   // 12: rows of cof(A) (A = the 3x3 part), 4th of each row unused
#define SFFD_FRAME_BREAKS 24u       // distinct knot values of u, then v, then w

// outside_mode values: what happens to a point outside the lattice box.
#define SFFD_OUTSIDE_EXTRAPOLATE 0u   // evaluate the nearest knot box's polynomial (continuous)
#define SFFD_OUTSIDE_KEEP 1u          // leave the point and its normal unmoved, as PyGeM does

// What a kernel that evaluates the lattice may be compiled to assume, as bits of one specialization
// constant (Vulkan; a define on OpenGL): the host names what its lattice and parameter block hold, and
// the code for the other case is dropped before the driver generates machine code (llvmpipe and
// lavapipe do that at the first dispatch, and every storage-buffer read is much code there). 0: no
// assumption, every case decided at run time. Results are the same either way.
#define SFFD_SPEC_ASSUMPTIONS 0
#define SFFD_ASSUME_DEGREE2 1u             // degree 2 on every axis
#define SFFD_ASSUME_GENERAL_DEGREE 2u      // any other degrees
#define SFFD_ASSUME_LATTICE_IN_PARAMS 4u   // the parameter block's inline_lattice holds the lattice
#define SFFD_ASSUME_LATTICE_IN_STORAGE 8u  // the lattice storage buffers hold it
#define SFFD_ASSUME_FIT_IN_PARAMS 16u      // inline_lattice holds all the kernel's constant tables (DeformParams:
                                           // the fit table; AccurateParams: A_n^{-1} and the tessellation basis)
#define SFFD_ASSUME_FIT_IN_STORAGE 32u     // the lattice frame range holds all of them
#define SFFD_ASSUME_ROLLED_LOOPS 64u       // keep the loops bounded by sffdRolled() rolled (prelude.glsl)
#define SFFD_ASSUME_LOOSE_DIVISION 128u    // strict kernels: the driver's a / b and sqrt may miss the correctly
                                           // rounded result, so round them (correctly_rounded.h)
#define SFFD_ASSUME_ONE_SAMPLE_SITE 256u   // deform_smooth: the boundary's corners and edge points in one loop, one
                                           // lattice evaluation in its code: quicker to translate, slower to run
                                           // (a one-shot job on lavapipe below Mesa 23: kernel_registry.cpp forDevice)

// The lattice part of every parameter block.
SFFD_STRUCT_BEGIN(LatticeParams)
  SFFD_UVEC4 degree;         // xyz: degree per axis (1..SFFD_MAX_DEGREE); w: outside_mode
  SFFD_UVEC4 boxes;          // xyz: knot boxes per axis; w: coefficients per box
  SFFD_UVEC4 break_offset;   // xyz: first break of each axis in the frame buffer; w: where the parameter
                             // block's inline_lattice holds the coefficients (0: not there; DeformParams,
                             // AccurateParams)
SFFD_STRUCT_END(LatticeParams)

// ---- kernel classic_ffd: one thread per vertex, deforms the position and normal ----
// Four storage blocks in all (the OpenGL ES 3.1 minimum): the lattice, the vertices in, the vertices
// out, each range holding the positions and, from element range.z on, the normals.
#define SFFD_BINDING_CLASSIC_IN SFFD_SLOT_3    // real4 per vertex: positions (w ignored), then normals (w ignored)
#define SFFD_BINDING_CLASSIC_OUT SFFD_SLOT_4   // real4 per vertex: positions (w = 1 inside the lattice box, 0
                                               // outside), then unit normals (w = 0)

SFFD_STRUCT_BEGIN(ClassicParams)
  SFFD_STRUCT_MEMBER(LatticeParams, lattice)
  SFFD_UVEC4 range;          // x: first vertex of this chunk (relative to the bound ranges), y: vertex count,
                             // z: the element where the normals begin in both ranges
SFFD_STRUCT_END(ClassicParams)

// ---- kernel pn_triangles: one thread per original triangle (METHOD.md 3.2) ----
// Mesh buffers shared by the pre-compute kernels, in slots 1..4 (ES 3.1 guarantees 4 storage blocks at
// bindings 0..3). The vertices' range holds the positions and, from the element range.z of PnParams and
// ClipParams names, the normals.
#define SFFD_BINDING_MESH_VERTICES SFFD_SLOT_1       // real4 per vertex: positions (w unused), then unit normals (w unused)
#define SFFD_BINDING_MESH_TRIANGLES SFFD_SLOT_2      // 2 uvec4 per triangle: vertex ids (w unused), weld ids (w unused)
#define SFFD_BINDING_MESH_SLOT_NORMALS SFFD_SLOT_3   // 12 real4 per triangle: per corner slot, the first then the second
                                           // normal of the slot (w of the first: 1 crease, 0 smooth;
                                           // w of the second: 1 when the first is the triangle's own)
#define SFFD_BINDING_PN_OUT SFFD_SLOT_4              // SFFD_PN_STRIDE real4 per triangle
#define SFFD_MESH_TRIANGLE_STRIDE 2u
#define SFFD_SLOT_NORMAL_STRIDE 12u
// PN record: the 10 cubic geometry control points (linear index order 300,210,201,120,111,102,030,021,012,003)
// then the 6 quadratic normal control points (200,110,101,020,011,002).
#define SFFD_PN_STRIDE 16u
#define SFFD_PN_NORMALS 10u

// ---- kernels clip_count and clip_write: regular clipping by the split-pattern table (METHOD.md 4.2) ----
// One thread per clip triangle (an original triangle, or a piece of one after the pre-split of
// triangles whose edges need more than Nmax segments). Four storage blocks in all (the OpenGL ES 3.1
// minimum): two input ranges of sections at the elements ClipParams names, and the two outputs. Each
// section begins at a multiple of SFFD_SECTION_ALIGN bytes, so that pn_triangles binds the mesh's
// sections and writes the PN records as ranges of their own. A mesh beyond one binding is cut into
// pre-compute chunks of consecutive parents, each with ranges of its own laid out the same way (all
// the vertices, then that chunk's parents and clip triangles).
#define SFFD_BINDING_CLIP_REALS SFFD_SLOT_1      // real4: the mesh vertices (positions, then normals from element
                                                 // range.z); from element sections.x the slot normals
                                                 // (SFFD_SLOT_NORMAL_STRIDE per triangle); from sections.y the PN
                                                 // records (SFFD_PN_STRIDE per triangle); from sections.z per clip
                                                 // triangle SFFD_CLIP_REAL_STRIDE: lam[3], flat[3], edge params[3]
#define SFFD_BINDING_CLIP_WORDS SFFD_SLOT_2      // uint: the split table (pattern entries, 4 each; then vertices, 4
                                                 // each: lambda bits, edge | step << 16; then packed uint16 triangle
                                                 // indices); from word words.x the mesh triangles (4 per uvec4 of
                                                 // SFFD_BINDING_MESH_TRIANGLES); from words.y per clip triangle
                                                 // 4 * SFFD_CLIP_HEADER_STRIDE: (parent, corner kinds, 0, 0), corner
                                                 // weld ids; from words.z one per clip triangle: its sub-triangle
                                                 // count (clip_count writes), its exclusive offset (clip_write reads)
#define SFFD_BINDING_SUB_HEADERS SFFD_SLOT_3     // uvec4 per sub-triangle: parent, crease slot bits, 0, 0
#define SFFD_BINDING_SUB_RECORDS SFFD_SLOT_4     // SFFD_SUB_STRIDE real4 per sub-triangle
#define SFFD_SECTION_ALIGN 256u                  // the largest storage offset alignment GL and Vulkan allow
#define SFFD_CLIP_HEADER_STRIDE 2u
#define SFFD_CLIP_REAL_STRIDE 9u
// Corner kinds of a clip triangle (packed 8 bits each in header.y): the corner is parent corner k (0..2),
// lies on parent edge e (3 + e) at the parameter in its edge params, or inside the parent (6).
#define SFFD_CORNER_INTERIOR 6u
// Edge params of clip edge e (corner e -> corner e+1): x = parent edge it lies on (-1: none),
// y = parameter of corner e along that parent edge, z = of corner e+1; parameters are measured from
// the parent edge's endpoint with the lower weld id.
// Sub-triangle record (METHOD.md 3.3): lam[3], x_pn[3], x_flat[3], n_lin[3], n_pn[3], n_nbr[6].
#define SFFD_SUB_STRIDE 21u
#define SFFD_SUB_LAM 0u
#define SFFD_SUB_XPN 3u
#define SFFD_SUB_XFLAT 6u
#define SFFD_SUB_NLIN 9u
#define SFFD_SUB_NPN 12u
#define SFFD_SUB_NNBR 15u
// The crease slot bits (header.y, 6 bits) again, as the integer-valued real w of the record's first
// element: the deform kernels read them there and bind no uint range.
#define SFFD_SUB_CREASE_BITS SFFD_SUB_LAM

SFFD_STRUCT_BEGIN(ClipParams)
  SFFD_UVEC4 range;      // x: first clip triangle, y: clip triangle count, z: the first normal of the reals' range,
                         // w: the parent of the per-parent sections' first entry (the mesh triangles, slot normals
                         // and PN records of a pre-compute chunk; parent ids in the clip headers are the mesh's)
  SFFD_UVEC4 table;      // x: Nmax, y: first vertex word, z: first triangle word (of the split table)
  SFFD_VEC4 target;      // x: target edge length l
  SFFD_UVEC4 sections;   // first element in the reals' range of x: the slot normals, y: the PN records, z: the clip triangles
  SFFD_UVEC4 words;      // first word in the words' range of x: the mesh triangles, y: the clip headers, z: the counts
SFFD_STRUCT_END(ClipParams)

// ---- kernel deform_smooth: the deform stage of smooth FFD, one thread per sub-triangle (METHOD.md 3.4) ----
// Four storage blocks in all (the OpenGL ES 3.1 minimum), the split kernels too: bindings 1 and 2 are
// the lattice (lattice_eval.glsl), the lattice frame range holding the fit table from the real
// DeformParams.sections.y names; the sub-triangle records; one output range of sections. The one header
// field the kernels need, the crease slot bits, rides in the records (SFFD_SUB_CREASE_BITS).
#define SFFD_BINDING_DEFORM_SUB_RECORDS SFFD_SLOT_3  // SFFD_SUB_STRIDE real4 per sub-triangle (clip_write's records)
#define SFFD_BINDING_DEFORM_OUT SFFD_SLOT_4          // real4, per sub-triangle of the chunk: the tessellation (positions,
                                                     // then normals; first, so that it can be drawn from the range);
                                                     // from element sections.z the SFFD_PATCH_STRIDE patch control
                                                     // points; from element sections.w (split form) the samples
// Fitting point record: lambda (3), weight w of the centre fit, then the 10 cubic Bernstein values.
#define SFFD_FIT_STRIDE 14u
// Patch record: 10 geometry control points, then 10 normal control points (linear index order).
#define SFFD_PATCH_STRIDE 20u
#define SFFD_MAX_FIT_POINTS 91   // interior points of the degree-15 lattice: s <= 15
// Split form (kernels deform_step_sample, _fit, _adjust, _tessellate): the samples of one sub-triangle,
// SFFD_SAMPLE_FIXED + (interior fitting points) real4: Q[3], QN[3], E[6], EN[6], adj[3], adjNbr[6], then
// the interior sample normals.
#define SFFD_SAMPLE_FIXED 27u

// The deform (and accurate) kernels' parameter block also carries the lattice itself (float variants,
// when it fits):
// on llvmpipe/lavapipe a uniform-buffer read is a vector load or gather, while every storage-buffer
// read is a loop over the SIMD lanes, which made lattice evaluation several times slower. 16 KiB in
// all, the smallest uniform block every GL 4.3 and Vulkan device accepts. lattice.break_offset.w is
// then the first vec4 of the Bezier coefficients in inline_lattice (the frame reals come first, four
// to a vec4); 0 means the kernel reads the lattice storage buffers instead (f64, or too large).
// The fit table follows the lattice there when it fits too (sections.x: its first vec4, 0: read
// it from the lattice frame range; lattice_eval.glsl's latticeTableAt).
#define SFFD_INLINE_LATTICE_VEC4 1015
SFFD_STRUCT_BEGIN(DeformParams)
  SFFD_STRUCT_MEMBER(LatticeParams, lattice)
  SFFD_UVEC4 range;    // x: first sub-triangle, y: count, z: interior fitting points, w: tessellation level
  SFFD_UVEC4 sections;   // x: first vec4 of the fit table in inline_lattice (0: not there), y: its first real
                         // in the lattice frame range; z: first patch element, w: first sample element
                         // (SFFD_BINDING_DEFORM_OUT)
  SFFD_VEC4 inline_lattice[SFFD_INLINE_LATTICE_VEC4];
SFFD_STRUCT_END(DeformParams)

SFFD_STRUCT_BEGIN(PnParams)
  SFFD_UVEC4 range;   // x: first triangle, y: triangle count, z: the first normal of the vertices' range
SFFD_STRUCT_END(PnParams)

// ---- kernel accurate_patches (accurate FFD, METHOD.md 2; owner: accurate FFD) ----
// Three dispatches a chunk of knot-box sub-triangles (range.z selects the stage), so that no invocation
// runs more than m^2 loop iterations (18,496 at n = 15; llvmpipe ends every invocation after 65535 in all):
//   stage 0, a thread per (sub-triangle, sample l): S_l = R(x(l/n)) at the principal lattice points;
//   stage 1, a thread per sub-triangle: P_k = sum_l A_n^{-1}[k][l] S_l (k, then l ascending; every lane
//     reads the same entry of A_n^{-1} at a time);
//   stage 2, a thread per (sub-triangle, tessellation vertex): position and normal (patch_output.h layout).
#define SFFD_ACC_MAX_DEGREE 15           // 3 * SFFD_MAX_DEGREE
#define SFFD_ACC_MAX_CP 136              // (n+1)(n+2)/2 for n = SFFD_ACC_MAX_DEGREE
#define SFFD_ACC_STAGE_SAMPLES 0u
#define SFFD_ACC_STAGE_PATCHES 1u
#define SFFD_ACC_STAGE_TESSELLATE 2u
// Threads a sub-triangle of a stage's dispatch (m control points, nv tessellation vertices).
#define SFFD_ACC_THREADS_PER_SUB(stage, m, nv) \
  ((stage) == SFFD_ACC_STAGE_TESSELLATE ? (nv) : (stage) == SFFD_ACC_STAGE_PATCHES ? 1u : (m))
// Four storage blocks in all (the OpenGL ES 3.1 minimum): the lattice's two, and two of sections.
// The lattice frame range also holds, from the reals AccurateParams.tables names, the constant tables:
//   A_n^{-1} transposed, entry (sample l, control point k) at l*m + k;
//   the tessellation basis: per tessellation vertex v, B^n_k(lambda_v) for the m control points k.
#define SFFD_BINDING_ACC_CHUNK SFFD_SLOT_3     // real4, per sub-triangle of the chunk: nv tessellation positions
                                               // (stage 2 writes), from element sections.x nv unit geometric normals
                                               // of the patch, cof(J) n_face (stage 2), from element sections.y
                                               // SFFD_ACC_CORNER_STRIDE corners: the flat corners sum_i lam_i V_i,
                                               // the parent's unit face normal (read)
#define SFFD_BINDING_ACC_SCRATCH SFFD_SLOT_4   // real4, per sub-triangle: m samples S_l (stage 0 writes, stage 1
                                               // reads), from element sections.z m patch control points, linear
                                               // index order (stage 1 writes, stage 2 reads)
#define SFFD_ACC_CORNER_STRIDE 4u

SFFD_STRUCT_BEGIN(AccurateParams)
  SFFD_STRUCT_MEMBER(LatticeParams, lattice)
  SFFD_UVEC4 range;      // x: first sub-triangle of this chunk (relative to the bound ranges), y: sub-triangle count, z: stage
  SFFD_UVEC4 shape;      // x: patch degree n, y: control points m = (n+1)(n+2)/2, z: tessellation level L, w: vertices (L+1)(L+2)/2
  SFFD_UVEC4 sections;   // x: first normal, y: first corner (elements of the chunk range); z: first control point (scratch)
  SFFD_UVEC4 tables;     // x: first real of A_n^{-1}, y: first real of the tessellation basis (lattice frame range);
                         // z, w: their first vec4 in inline_lattice (0: that one is read from the frame range)
  SFFD_VEC4 inline_lattice[SFFD_INLINE_LATTICE_VEC4];   // as DeformParams's: the lattice, then the tables that fit
SFFD_STRUCT_END(AccurateParams)
// ---- end of accurate_patches ----

#endif
