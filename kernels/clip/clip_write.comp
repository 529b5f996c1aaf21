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
  ClipSetup S = clipSetup(ct);
  ClipTriangle T = loadClipTriangle(ct);
  Parent par = loadParent(T.parent);
  // Per local clip edge: the parent edge it lies on and the neighbour's normal there (crease edges).
  EdgeNeighbour nbr[3];
  for (uint le = 0u; le < 3u; ++le) nbr[le] = edgeNeighbour(par, T.edgeParams[le].x);
  uint out0 = counts(ct);
  for (uint k = 0u; k < S.entry.w; ++k) {
    // Per corner c of the sub-triangle: its pattern vertex's edge and step, and its site's kind and
    // parameter, as vector components (see ClipSetup), for the crease test of its sub-edges.
    uvec3 edge, step, kind;
    real3 siteT;
    real3 npn0, npn1, npn2;
    uint o = out0 + k;
    uint rec = SFFD_SUB_STRIDE * o;
    real3 lam0;
    for (uint c = 0u; c < sffdRolled(3u); ++c) {
      uint i = 3u * (S.entry.z + k) + (S.odd && c != 0u ? 3u - c : c);   // odd: corners 1 and 2 swapped
      uint word = splitTable(params.table.z + i / 2u);
      uint idx = (i % 2u == 0u) ? (word & 65535u) : (word >> 16u);
      uint v = params.table.y + 4u * (S.entry.x + idx);
      real3 lamCanon = real3(uintBitsToFloat(splitTable(v)), uintBitsToFloat(splitTable(v + 1u)), uintBitsToFloat(splitTable(v + 2u)));
      uint w = splitTable(v + 3u);
      edge[c] = w & 255u;
      step[c] = w >> 16u;
      Site site = patternSite(T, S, edge[c], step[c], lamCanon);
      kind[c] = site.kind;
      siteT[c] = site.t;
      SiteValue val = evaluateSite(par, site);
      subRecords[rec + SFFD_SUB_LAM + c] = real4(val.lam, 0);
      subRecords[rec + SFFD_SUB_XPN + c] = real4(val.xpn, 0);
      subRecords[rec + SFFD_SUB_XFLAT + c] = real4(val.xflat, 0);
      subRecords[rec + SFFD_SUB_NLIN + c] = real4(val.nlin, 0);
      subRecords[rec + SFFD_SUB_NPN + c] = real4(val.npn, 0);
      if (c == 0u) lam0 = val.lam, npn0 = val.npn;
      if (c == 1u) npn1 = val.npn;
      if (c == 2u) npn2 = val.npn;
    }
    // Sub-edge j joins corners j and d = j + 2: slot 2j (at corner j, towards d) and slot 2d + 1 (at d,
    // towards j). Where it lies on a crease edge of the parent, each slot holds the neighbour's normal
    // at its corner's site (w = 1), else the corner's own PN normal. The shared edge and the neighbour
    // are found once a sub-edge.
    uint creaseBits = 0u;
    for (uint j = 0u; j < sffdRolled(3u); ++j) {
      uint d = (j + 2u) % 3u;
      uint ce = sharedCanonicalEdge(edge[j], step[j], edge[d], step[d]);
      uint a = S.perm[ce % 3u], b = S.perm[(ce + 1u) % 3u];
      uint le = (b == (a + 1u) % 3u) ? a : b;
      EdgeNeighbour n = le == 0u ? nbr[0] : (le == 1u ? nbr[1] : nbr[2]);
      bool crease = ce < 3u && n.crease;
      real4 nj = real4(j == 0u ? npn0 : (j == 1u ? npn1 : npn2), 0);
      real4 nd = real4(d == 0u ? npn0 : (d == 1u ? npn1 : npn2), 0);
      if (crease) {
        nj = real4(neighbourNormalAt(n, siteParamOnEdge(par, kind[j], siteT[j], n.e)), 1);
        nd = real4(neighbourNormalAt(n, siteParamOnEdge(par, kind[d], siteT[d], n.e)), 1);
        creaseBits |= (1u << (2u * j)) | (1u << (2u * d + 1u));
      }
      subRecords[rec + SFFD_SUB_NNBR + 2u * j] = nj;
      subRecords[rec + SFFD_SUB_NNBR + 2u * d + 1u] = nd;
    }
    subRecords[rec + SFFD_SUB_CREASE_BITS] = real4(lam0, real(creaseBits));
    subHeaders[o] = uvec4(par.id, creaseBits, 0u, 0u);
  }
}
