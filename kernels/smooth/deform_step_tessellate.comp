#version 450
// Split deform, step 6 (METHOD.md 3.4): tessellation of the patches at level L.
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#include "smooth_deform.glsl"
layout(std430, SFFD_SET binding = SFFD_BINDING_DEFORM_OUT) buffer DeformOut { real4 deformOut[]; };

void main() {
  uint tid = sffdThreadIndex();
  if (tid >= params.range.y) return;
  uint st = params.range.x + tid;
  uint pbase = SFFD_PATCH_STRIDE * st;
  real3 cp[10], ncp[10];
  for (uint k = 0u; k < 10u; ++k) { cp[k] = patches(pbase + k).xyz; ncp[k] = patches(pbase + 10u + k).xyz; }
  uint L = params.range.w;
  uint nv = (L + 1u) * (L + 2u) / 2u;
  uint tbase = 2u * nv * st;
  for (uint r = 0u; r <= L; ++r)
    for (uint t = 0u; t <= r; ++t) {
      real3 x, n;
      smoothTessVertex(cp, ncp, L, r, t, x, n);
      uint v = r * (r + 1u) / 2u + t;
      tess(tbase + v) = real4(x, 0);
      tess(tbase + nv + v) = real4(n, 0);
    }
}
