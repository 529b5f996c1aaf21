#version 450
// Split deform, step 5 (METHOD.md 3.4): edge control points onto the tangent plane or crease line.
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#include "smooth_deform.glsl"

void main() {
  uint tid = sffdThreadIndex();
  if (tid >= params.range.y) return;
  uint st = params.range.x + tid;
  uint b = (SFFD_SAMPLE_FIXED + params.range.z) * st;
  real3 adj[3], adjNbr[6], cp[10];
  for (uint c = 0u; c < 3u; ++c) adj[c] = samples(b + 18u + c).xyz;
  for (uint e = 0u; e < 6u; ++e) adjNbr[e] = samples(b + 21u + e).xyz;
  uint pbase = SFFD_PATCH_STRIDE * st;
  for (uint k = 0u; k < 10u; ++k) cp[k] = patches(pbase + k).xyz;
  smoothAdjust(smoothCreaseBits(st), adj, adjNbr, cp);
  for (uint k = 0u; k < 10u; ++k) patches(pbase + k) = real4(cp[k], 0);
}
