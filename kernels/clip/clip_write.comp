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
  Parent par = loadParent(clipHeaders(SFFD_CLIP_HEADER_STRIDE * ct).x);
  uint out0 = counts(ct);
  for (uint k = 0u; k < S.entry.w; ++k) {
    uint idx[3], edge[3], step[3];
    for (uint c = 0u; c < 3u; ++c) {
      uint i = 3u * (S.entry.z + k) + c;
      uint word = splitTable(params.table.z + i / 2u);
      idx[c] = (i % 2u == 0u) ? (word & 65535u) : (word >> 16u);
    }
    if (S.odd) { uint x = idx[1]; idx[1] = idx[2]; idx[2] = x; }
    Site site[3];
    SiteValue val[3];
    for (uint c = 0u; c < sffdRolled(3u); ++c) {
      uint v = params.table.y + 4u * (S.entry.x + idx[c]);
      real3 lamCanon = real3(uintBitsToFloat(splitTable(v)), uintBitsToFloat(splitTable(v + 1u)), uintBitsToFloat(splitTable(v + 2u)));
      uint w = splitTable(v + 3u);
      edge[c] = w & 255u;
      step[c] = w >> 16u;
      site[c] = patternSite(ct, S, edge[c], step[c], lamCanon);
      val[c] = evaluateSite(par, site[c]);
    }
    uint o = out0 + k;
    uint rec = SFFD_SUB_STRIDE * o;
    uint creaseBits = 0u;
    for (uint c = 0u; c < sffdRolled(3u); ++c) {
      subRecords[rec + SFFD_SUB_LAM + c] = real4(val[c].lam, 0);
      subRecords[rec + SFFD_SUB_XPN + c] = real4(val[c].xpn, 0);
      subRecords[rec + SFFD_SUB_XFLAT + c] = real4(val[c].xflat, 0);
      subRecords[rec + SFFD_SUB_NLIN + c] = real4(val[c].nlin, 0);
      subRecords[rec + SFFD_SUB_NPN + c] = real4(val[c].npn, 0);
      // Slots 2c (towards corner c+2) and 2c+1 (towards c+1): the neighbour's normal where the
      // sub-edge lies on a crease edge of the parent.
      for (uint h = 0u; h < 2u; ++h) {
        uint d = h == 0u ? (c + 2u) % 3u : (c + 1u) % 3u;
        real4 nn = real4(val[c].npn, 0);
        uint ce = sharedCanonicalEdge(edge[c], step[c], edge[d], step[d]);
        if (ce < 3u) {
          uint a = S.perm[ce], b = S.perm[(ce + 1u) % 3u];
          uint le = (b == (a + 1u) % 3u) ? a : b;
          real pe = clipReals(SFFD_CLIP_REAL_STRIDE * ct + 6u + le).x;
          if (pe >= real(0)) {
            uint e = uint(pe);
            real4 nb = neighbourNormalOnEdge(par, e, siteParamOnEdge(par, site[c], e));
            if (nb.w > real(0.5)) {
              nn = nb;
              creaseBits |= 1u << (2u * c + h);
            }
          }
        }
        subRecords[rec + SFFD_SUB_NNBR + 2u * c + h] = nn;
      }
    }
    subRecords[rec + SFFD_SUB_CREASE_BITS] = real4(val[0].lam, real(creaseBits));
    subHeaders[o] = uvec4(par.id, creaseBits, 0u, 0u);
  }
}
