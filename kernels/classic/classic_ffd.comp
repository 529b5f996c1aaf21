#version 450
// Kernel classic_ffd: classic (vertex-only) FFD, one thread per vertex. Deforms the position by the
// lattice volume and the normal by the cofactor of its Jacobian (METHOD.md 1.4, 6).
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#include "../common/lattice_eval.glsl"

layout(std140, SFFD_SET binding = SFFD_BINDING_PARAMS) uniform ClassicBlock { ClassicParams params; };
layout(std430, SFFD_SET binding = SFFD_BINDING_CLASSIC_IN) readonly buffer VerticesIn { real4 vertIn[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_CLASSIC_OUT) writeonly buffer VerticesOut { real4 vertOut[]; };

void main() {
  uint t = sffdThreadIndex();
  if (t >= params.range.y) return;
  uint v = params.range.x + t;
  uint vn = params.range.z + v;   // its normal
  real3 x = vertIn[v].xyz;
  real3 n = vertIn[vn].xyz;
  LatticeSample S = latticeEvaluate(params.lattice, x);
  if (!S.inside && params.lattice.degree.w == SFFD_OUTSIDE_KEEP) {
    vertOut[v] = real4(x, 0);
    vertOut[vn] = real4(n, 0);
    return;
  }
  vertOut[v] = real4(S.value, S.inside ? 1 : 0);
  vertOut[vn] = real4(snormalize(latticeCofactorNormal(S, n)), 0);
}
