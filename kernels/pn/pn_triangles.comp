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

// Control point of each slot in the cubic linear index order (METHOD.md 3.3).
const uint kSlotControlPoint[6] = uint[6](2u, 1u, 3u, 7u, 8u, 5u);

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
  real3 cp[10];
  cp[0] = V[0];
  cp[6] = V[1];
  cp[9] = V[2];
  P real3 edgeSum = real3(0);
  for (uint s = 0u; s < 6u; ++s) {
    uint c = s / 2u;
    uint other = (s % 2u == 1u) ? (c + 1u) % 3u : (c + 2u) % 3u;
    real4 nFirst = slotNormals[SFFD_SLOT_NORMAL_STRIDE * tri + 2u * s];
    real3 nSecond = slotNormals[SFFD_SLOT_NORMAL_STRIDE * tri + 2u * s + 1u].xyz;
    real3 b = pnEdgePoint(V[c], V[other], nFirst, nSecond);
    cp[kSlotControlPoint[s]] = b;
    edgeSum = edgeSum + b;
  }
  P real3 E = edgeSum / real(6);
  P real3 Vm = ((V[0] + V[1]) + V[2]) / real(3);
  P real3 centre = E + (E - Vm) / real(2);
  cp[4] = centre;

  uint base = SFFD_PN_STRIDE * tri;
  for (uint i = 0u; i < 10u; ++i) pn[base + i] = real4(cp[i], 0);
  // Normal control points; each edge's middle one computed in weld-id order.
  pn[base + SFFD_PN_NORMALS + 0u] = real4(N[0], 0);
  pn[base + SFFD_PN_NORMALS + 3u] = real4(N[1], 0);
  pn[base + SFFD_PN_NORMALS + 5u] = real4(N[2], 0);
  const uint kEdgeNormalIndex[3] = uint[3](1u, 4u, 2u);   // edges (0,1) -> 110, (1,2) -> 011, (2,0) -> 101
  for (uint e = 0u; e < 3u; ++e) {
    uint a = e, b = (e + 1u) % 3u;
    if (welds[b] < welds[a]) { uint x = a; a = b; b = x; }
    pn[base + SFFD_PN_NORMALS + kEdgeNormalIndex[e]] = real4(pnEdgeNormal(V[a], V[b], N[a], N[b]), 0);
  }
}
