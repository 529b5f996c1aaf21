#version 450
// Kernel pn_triangles (K1 of METHOD.md 3.2): one thread per original triangle; the cubic PN
// geometry patch (10 control points) and the quadratic normal patch (6), creases kept sharp.
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#include "pn_eval.glsl"

layout(std140, SFFD_SET binding = SFFD_BINDING_PARAMS) uniform PnBlock { PnParams params; };
layout(std430, SFFD_SET binding = SFFD_BINDING_MESH_VERTICES) readonly buffer Vertices { real4 vertices[]; };
#define positions(i) vertices[i]
#define normals(i) vertices[params.range.z + (i)]
layout(std430, SFFD_SET binding = SFFD_BINDING_MESH_TRIANGLES) readonly buffer Triangles { uvec4 triangles[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_MESH_SLOT_NORMALS) readonly buffer SlotNormals { real4 slotNormals[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_PN_OUT) writeonly buffer PnOut { real4 pn[]; };

// The reads, the per-slot and per-edge work and the stores one at a time in loops bounded by
// sffdRolled (prelude.glsl: why), the values through shift registers (arrays indexed by constants
// only: registers). Same arithmetic in the same order, same bits.
void main() {
  uint t = sffdThreadIndex();
  if (t >= params.range.y) return;
  uint tri = params.range.x + t;
  uvec4 ids, welds;
  if (!sffdRollsLoops()) {
    ids = triangles[SFFD_MESH_TRIANGLE_STRIDE * tri];
    welds = triangles[SFFD_MESH_TRIANGLE_STRIDE * tri + 1u];
  } else {
    for (uint i = 0u; i < sffdRolled(2u); ++i) {
      ids = welds;
      welds = triangles[SFFD_MESH_TRIANGLE_STRIDE * tri + i];
    }
  }
  real3 q[6];   // positions(ids[0..2]), then normals(ids[0..2])
  for (uint i = 0u; i < sffdRolled(6u); ++i) {
    for (uint j = 0u; j < 5u; ++j) q[j] = q[j + 1u];
    q[5] = vertices[(i < 3u ? 0u : params.range.z) + ids[i % 3u]].xyz;
  }
  real3 V0 = q[0], V1 = q[1], V2 = q[2], N0 = q[3], N1 = q[4], N2 = q[5];
  // The edge control points of slots 0..5 (control points 2, 1, 3, 7, 8, 5).
  real3 b[6];
  P real3 edgeSum = real3(0);
  for (uint s = 0u; s < sffdRolled(6u); ++s) {
    uint c = s / 2u;
    uint other = (s % 2u == 1u) ? (c + 1u) % 3u : (c + 2u) % 3u;
    real4 nFirst = slotNormals[SFFD_SLOT_NORMAL_STRIDE * tri + 2u * s];
    // Read for a crease slot only, the one pnEdgePoint uses it in: most slots are none, and lavapipe reads
    // in a branch only for the lanes in it (clip_sites.glsl loadParent).
    real3 nSecond = real3(0);
    if (nFirst.w > real(0.5)) nSecond = slotNormals[SFFD_SLOT_NORMAL_STRIDE * tri + 2u * s + 1u].xyz;
    real3 Vc = c == 0u ? V0 : (c == 1u ? V1 : V2), Vo = other == 0u ? V0 : (other == 1u ? V1 : V2);
    real3 e = pnEdgePoint(Vc, Vo, nFirst, nSecond);
    for (uint j = 0u; j < 5u; ++j) b[j] = b[j + 1u];
    b[5] = e;
    edgeSum = edgeSum + e;
  }
  P real3 E = sdiv(edgeSum, real(6));
  P real3 V3 = (V0 + V1) + V2;
  P real3 Vm = sdiv(V3, real(3));
  P real3 centre = E + (E - Vm) / real(2);
  // Each edge's middle normal control point, computed in weld-id order: edges (0,1) -> 110, (1,2) -> 011, (2,0) -> 101.
  real3 en[3];
  for (uint e = 0u; e < sffdRolled(3u); ++e) {
    uint a = e, c = (e + 1u) % 3u;
    if (welds[c] < welds[a]) { uint x = a; a = c; c = x; }
    real3 Va = a == 0u ? V0 : (a == 1u ? V1 : V2), Vb = c == 0u ? V0 : (c == 1u ? V1 : V2);
    real3 Na = a == 0u ? N0 : (a == 1u ? N1 : N2), Nb = c == 0u ? N0 : (c == 1u ? N1 : N2);
    en[0] = en[1];
    en[1] = en[2];
    en[2] = pnEdgeNormal(Va, Vb, Na, Nb);
  }
  // The record (SFFD_PN_NORMALS = 10, SFFD_PN_STRIDE = 16, asserted in pn_triangles.cpp): control
  // points 0..9, then the normal control points 200, 110, 101, 020, 011, 002.
  real3 r[16] = real3[16](V0, b[1], b[0], b[2], centre, b[5], V1, b[3], b[4], V2, N0, en[0], en[2], N1, en[1], N2);
  uint base = SFFD_PN_STRIDE * tri;
  for (uint i = 0u; i < sffdRolled(16u); ++i) {
    pn[base + i] = real4(r[0], 0);
    for (uint j = 0u; j < 15u; ++j) r[j] = r[j + 1u];
  }
}
