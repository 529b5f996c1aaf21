#version 450
// Kernel clip_write: per clip triangle, writes its sub-triangle records at its scanned offset, in
// pattern order, so the output is deterministic (METHOD.md 3.3, 4.2).
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#include "clip_sites.glsl"

layout(std430, SFFD_SET binding = SFFD_BINDING_SUB_HEADERS) writeonly buffer SubHeaders { uvec4 subHeaders[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_SUB_RECORDS) writeonly buffer SubRecords { real4 subRecords[]; };

void main() {
  uint t = sffdThreadIndex();
  if (t >= params.range.y) return;
  uint ct = params.range.x + t;
  ClipTriangle T = loadClipTriangle(ct);
  ClipSetup S;
  if (sffdRollsLoops()) S = clipSetupOf(T.welds, T.flatCorner);   // its records read once (loadClipTriangle)
  else S = clipSetup(ct);
  Parent par = loadParent(T.parent, !cornerSitesOnly(T, S));
  // Per local clip edge: the parent edge it lies on and the neighbour's normal there (crease edges).
  // A rolled loop (one copy of the reads, see loadParent), the results through a shift register.
  EdgeNeighbour nbr0, nbr1, nbr2;
  for (uint le = 0u; le < sffdRolled(3u); ++le) {
    nbr0 = nbr1;
    nbr1 = nbr2;
    nbr2 = edgeNeighbour(par, clipEdgeParams(T, le).x);
  }
  uint out0 = counts(ct);
  for (uint k = 0u; k < S.entry.w; ++k) {
    // Per corner c of the sub-triangle: its pattern vertex's edge and step, and its site's kind and
    // parameter, as vector components (see ClipSetup), for the crease test of its sub-edges.
    uvec3 edge = uvec3(0u), step = uvec3(0u), kind = uvec3(0u);
    real3 siteT = real3(0);
    real3 npn0, npn1, npn2;
    uint o = out0 + k;
    uint rec = SFFD_SUB_STRIDE * o;
    real3 lam0;
    for (uint c = 0u; c < sffdRolled(3u); ++c) {
      uint i = 3u * (S.entry.z + k) + (S.odd && c != 0u ? 3u - c : c);   // odd: corners 1 and 2 swapped
      uint word = splitTable(params.table.z + i / 2u);
      uint idx = (i % 2u == 0u) ? (word & 65535u) : (word >> 16u);
      uint v = params.table.y + 4u * (S.entry.x + idx);
      uvec4 vw = clipWords4(v);   // splitTable(v ..)
      real3 lamCanon = real3(uintBitsToFloat(vw.x), uintBitsToFloat(vw.y), uintBitsToFloat(vw.z));
      uint w = vw.w;
      edge = withComponent(edge, c, w & 255u);
      step = withComponent(step, c, w >> 16u);
      Site site = patternSite(T, S, w & 255u, w >> 16u, lamCanon);
      kind = withComponent(kind, c, site.kind);
      siteT = withComponent(siteT, c, site.t);
      SiteValue val = evaluateSite(par, site);
      if (!sffdRollsLoops()) {
        subRecords[rec + SFFD_SUB_LAM + c] = real4(val.lam, 0);
        subRecords[rec + SFFD_SUB_XPN + c] = real4(val.xpn, 0);
        subRecords[rec + SFFD_SUB_XFLAT + c] = real4(val.xflat, 0);
        subRecords[rec + SFFD_SUB_NLIN + c] = real4(val.nlin, 0);
        subRecords[rec + SFFD_SUB_NPN + c] = real4(val.npn, 0);
      } else {   // LAM, XPN, XFLAT, NLIN, NPN (layout.h: evenly apart), one store an iteration (see loadParent)
        real3 f[5] = real3[5](val.lam, val.xpn, val.xflat, val.nlin, val.npn);
        for (uint j = 0u; j < sffdRolled(5u); ++j) {
          subRecords[rec + SFFD_SUB_LAM + (SFFD_SUB_XPN - SFFD_SUB_LAM) * j + c] = real4(f[0], 0);
          for (uint m = 0u; m < 4u; ++m) f[m] = f[m + 1u];
        }
      }
      if (c == 0u) lam0 = val.lam, npn0 = val.npn;
      if (c == 1u) npn1 = val.npn;
      if (c == 2u) npn2 = val.npn;
    }
    uint creaseBits = 0u;
    for (uint slot = 0u; slot < sffdRolled(6u); ++slot) {
      // Slots 2c (towards corner c+2) and 2c+1 (towards c+1): the neighbour's normal where the
      // sub-edge lies on a crease edge of the parent. One rolled loop over the six: one copy of it.
      uint c = slot / 2u, h = slot % 2u;
      uint d = h == 0u ? (c + 2u) % 3u : (c + 1u) % 3u;
      real4 nn = real4(c == 0u ? npn0 : (c == 1u ? npn1 : npn2), 0);
      uint ce = sharedCanonicalEdge(edge[c], step[c], edge[d], step[d]);
      if (ce < 3u) {
        uint a = S.perm[ce], b = S.perm[(ce + 1u) % 3u];
        uint le = (b == (a + 1u) % 3u) ? a : b;
        EdgeNeighbour n = le == 0u ? nbr0 : (le == 1u ? nbr1 : nbr2);
        if (n.crease) {
          nn = real4(neighbourNormalAt(n, siteParamOnEdge(par, kind[c], siteT[c], n.e)), 1);   // w = 1: a crease
          creaseBits |= 1u << (2u * c + h);
        }
      }
      subRecords[rec + SFFD_SUB_NNBR + 2u * c + h] = nn;
    }
    subRecords[rec + SFFD_SUB_CREASE_BITS] = real4(lam0, real(creaseBits));
    subHeaders[o] = uvec4(par.id, creaseBits, 0u, 0u);
  }
}
