#version 450
// Kernel classic_ffd: classic (vertex-only) FFD, one thread per vertex. Deforms the position by the
// lattice volume and the normal by the cofactor of its Jacobian (METHOD.md 1.4, 6).
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#include "../common/lattice_eval.glsl"

layout(std140, SFFD_SET binding = SFFD_BINDING_PARAMS) uniform ClassicBlock { ClassicParams params; };
layout(std430, SFFD_SET binding = SFFD_BINDING_CLASSIC_POS_IN) readonly buffer PosIn { real4 posIn[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_CLASSIC_NRM_IN) readonly buffer NrmIn { real4 nrmIn[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_CLASSIC_POS_OUT) writeonly buffer PosOut { real4 posOut[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_CLASSIC_NRM_OUT) writeonly buffer NrmOut { real4 nrmOut[]; };

void main() {
  uint t = sffdThreadIndex();
  if (t >= params.range.y) return;
  uint v = params.range.x + t;
  real3 x = posIn[v].xyz;
  real3 n = nrmIn[v].xyz;
  LatticeSample S = latticeEvaluate(params.lattice, x);
  if (!S.inside && params.lattice.degree.w == SFFD_OUTSIDE_KEEP) {
    posOut[v] = real4(x, 0);
    nrmOut[v] = real4(n, 0);
    return;
  }
  posOut[v] = real4(S.value, S.inside ? 1 : 0);
  nrmOut[v] = real4(snormalize(latticeCofactorNormal(S, n)), 0);
}
