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

// One thread a triangle, written out without local arrays: on lavapipe a local array indexed by a
// loop counter or a table lives in memory, read and written lane by lane. The edge points and normals
// are computed in the order the loops of the C++ twin (pnBuild, pn_eval.h) use, so the bits agree.
real3 edgePoint(uint tri, uint s, real3 Vc, real3 Vo) {
  real4 nFirst = slotNormals[SFFD_SLOT_NORMAL_STRIDE * tri + 2u * s];
  real3 nSecond = slotNormals[SFFD_SLOT_NORMAL_STRIDE * tri + 2u * s + 1u].xyz;
  return pnEdgePoint(Vc, Vo, nFirst, nSecond);
}

// The middle normal control point of edge (a, b), computed in weld-id order.
real3 edgeNormal(uvec4 welds, real3 Va, real3 Vb, real3 Na, real3 Nb, uint a, uint b) {
  bool swap = welds[b] < welds[a];
  return pnEdgeNormal(swap ? Vb : Va, swap ? Va : Vb, swap ? Nb : Na, swap ? Na : Nb);
}

void main() {
  uint t = sffdThreadIndex();
  if (t >= params.range.y) return;
  uint tri = params.range.x + t;
  uvec4 ids = triangles[SFFD_MESH_TRIANGLE_STRIDE * tri];
  uvec4 welds = triangles[SFFD_MESH_TRIANGLE_STRIDE * tri + 1u];
  real3 V0 = positions(ids.x).xyz, V1 = positions(ids.y).xyz, V2 = positions(ids.z).xyz;
  real3 N0 = normals(ids.x).xyz, N1 = normals(ids.y).xyz, N2 = normals(ids.z).xyz;
  // Slot s: corner s / 2, towards corner (s / 2 + 1) % 3 for odd s, (s / 2 + 2) % 3 for even s;
  // control points 2, 1, 3, 7, 8, 5 (kSlotCp).
  real3 b0 = edgePoint(tri, 0u, V0, V2);
  real3 b1 = edgePoint(tri, 1u, V0, V1);
  real3 b2 = edgePoint(tri, 2u, V1, V0);
  real3 b3 = edgePoint(tri, 3u, V1, V2);
  real3 b4 = edgePoint(tri, 4u, V2, V1);
  real3 b5 = edgePoint(tri, 5u, V2, V0);
  P real3 edgeSum = real3(0);
  edgeSum = edgeSum + b0;
  edgeSum = edgeSum + b1;
  edgeSum = edgeSum + b2;
  edgeSum = edgeSum + b3;
  edgeSum = edgeSum + b4;
  edgeSum = edgeSum + b5;
  P real3 E = edgeSum / real(6);
  P real3 Vm = ((V0 + V1) + V2) / real(3);
  P real3 centre = E + (E - Vm) / real(2);

  uint base = SFFD_PN_STRIDE * tri;
  pn[base + 0u] = real4(V0, 0);
  pn[base + 1u] = real4(b1, 0);
  pn[base + 2u] = real4(b0, 0);
  pn[base + 3u] = real4(b2, 0);
  pn[base + 4u] = real4(centre, 0);
  pn[base + 5u] = real4(b5, 0);
  pn[base + 6u] = real4(V1, 0);
  pn[base + 7u] = real4(b3, 0);
  pn[base + 8u] = real4(b4, 0);
  pn[base + 9u] = real4(V2, 0);
  // Normal control points 200, 110, 101, 020, 011, 002: edges (0,1) -> 110, (1,2) -> 011, (2,0) -> 101.
  pn[base + SFFD_PN_NORMALS + 0u] = real4(N0, 0);
  pn[base + SFFD_PN_NORMALS + 1u] = real4(edgeNormal(welds, V0, V1, N0, N1, 0u, 1u), 0);
  pn[base + SFFD_PN_NORMALS + 2u] = real4(edgeNormal(welds, V2, V0, N2, N0, 2u, 0u), 0);
  pn[base + SFFD_PN_NORMALS + 3u] = real4(N1, 0);
  pn[base + SFFD_PN_NORMALS + 4u] = real4(edgeNormal(welds, V1, V2, N1, N2, 1u, 2u), 0);
  pn[base + SFFD_PN_NORMALS + 5u] = real4(N2, 0);
}
