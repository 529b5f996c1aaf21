#version 450
// Split deform, step 6 (METHOD.md 3.4): tessellation of the patches at level L.
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#include "smooth_deform.glsl"

void main() {
  uint tid = sffdThreadIndex();
  if (tid >= params.range.y) return;
  uint st = params.range.x + tid;
  uint pbase = SFFD_PATCH_STRIDE * st;
  real3 cp[10], ncp[10];
  for (uint k = 0u; k < 10u; ++k) { cp[k] = patches(pbase + k).xyz; ncp[k] = patches(pbase + 10u + k).xyz; }
  uint L = params.range.w;
  smoothTessellate(cp, ncp, L, (L + 1u) * (L + 2u) * st);   // 2 * vertex count * st
}
