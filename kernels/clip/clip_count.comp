#version 450
// Kernel clip_count: per clip triangle, the number of sub-triangles its split pattern makes (the
// counting pass before the exclusive scan; METHOD.md 4.2 step 5).
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#define SFFD_CLIP_WRITES_COUNTS 1
#include "clip_sites.glsl"


void main() {
  uint t = sffdThreadIndex();
  if (t >= params.range.y) return;
  uint ct = params.range.x + t;
  counts(ct) = clipSetup(ct).entry.w;
}
