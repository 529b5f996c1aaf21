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

// The per-slot work and the stores in loops bounded by sffdRolled (prelude.glsl; on Mesa 25.0 the six
// slots and sixteen stores written out took most of this kernel's first dispatch), results through
// shift registers (arrays indexed by constants only: registers). Same arithmetic, same bits.
void main() {
  uint t = sffdThreadIndex();
  if (t >= params.range.y) return;
  uint tri = params.range.x + t;
  uvec4 ids = triangles[SFFD_MESH_TRIANGLE_STRIDE * tri];
  uvec4 welds = triangles[SFFD_MESH_TRIANGLE_STRIDE * tri + 1u];
  real3 V[3], N[3];
  for (uint c = 0u; c < 3u; ++c) {
    V[c] = positions(ids[c]).xyz;
    N[c] = normals(ids[c]).xyz;
  }
  // The edge control points of slots 0..5 (control points 2, 1, 3, 7, 8, 5).
  real3 b[6];
  P real3 edgeSum = real3(0);
  for (uint c = 0u; c < sffdRolled(3u); ++c) {   // corner c: slots 2c and 2c + 1
    for (uint j = 0u; j < 4u; ++j) b[j] = b[j + 2u];
    for (uint h = 0u; h < 2u; ++h) {
      uint s = 2u * c + h;
      uint other = h == 1u ? (c + 1u) % 3u : (c + 2u) % 3u;
      real4 nFirst = slotNormals[SFFD_SLOT_NORMAL_STRIDE * tri + 2u * s];
      real3 nSecond = slotNormals[SFFD_SLOT_NORMAL_STRIDE * tri + 2u * s + 1u].xyz;
      real3 Vc = c == 0u ? V[0] : (c == 1u ? V[1] : V[2]), Vo = other == 0u ? V[0] : (other == 1u ? V[1] : V[2]);
      real3 e = pnEdgePoint(Vc, Vo, nFirst, nSecond);
      b[4u + h] = e;
      edgeSum = edgeSum + e;
    }
  }
  real3 cp[10];
  cp[0] = V[0];
  cp[6] = V[1];
  cp[9] = V[2];
  cp[2] = b[0];
  cp[1] = b[1];
  cp[3] = b[2];
  cp[7] = b[3];
  cp[8] = b[4];
  cp[5] = b[5];
  P real3 E = edgeSum / real(6);
  P real3 Vm = ((V[0] + V[1]) + V[2]) / real(3);
  P real3 centre = E + (E - Vm) / real(2);
  cp[4] = centre;

  // Normal control points 200, 110, 101, 020, 011, 002; each edge's middle one computed in weld-id order.
  real3 en[3];
  for (uint e = 0u; e < 3u; ++e) {
    uint a = e, b = (e + 1u) % 3u;
    if (welds[b] < welds[a]) { uint x = a; a = b; b = x; }
    en[e] = pnEdgeNormal(V[a], V[b], N[a], N[b]);   // edges (0,1) -> 110, (1,2) -> 011, (2,0) -> 101
  }
  // The record (SFFD_PN_NORMALS = 10, SFFD_PN_STRIDE = 16, asserted in pn_triangles.cpp): eight stores in a rolled loop of two.
  real3 r[16] = real3[16](cp[0], cp[1], cp[2], cp[3], cp[4], cp[5], cp[6], cp[7], cp[8], cp[9], N[0], en[0], en[2], N[1], en[1], N[2]);
  uint base = SFFD_PN_STRIDE * tri;
  for (uint h = 0u; h < sffdRolled(2u); ++h)
    for (uint j = 0u; j < 8u; ++j) pn[base + 8u * h + j] = real4(h == 0u ? r[j] : r[8u + j], 0);
}
