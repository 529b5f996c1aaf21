// kernels/clip/clip_sites.glsl: regular clipping by the split-pattern table (Lu & Feng; METHOD.md 4.2),
// shared by the kernels clip_count and clip_write. The C++ twin is kernels/clip/clip_sites_cpu.cpp.
//
// Crack-freeness rests on three rules: (1) edge lengths and counts are computed from the endpoint with
// the lower weld id; (2) a boundary vertex's parameter along its edge is read from the table, whose
// pairs are bit-symmetric (split_pattern_table.h); (3) points on a parent edge are evaluated on that
// edge's PN curve from its lower-weld endpoint, from data both triangles hold identically.
#ifndef SFFD_CLIP_GLSL
#define SFFD_CLIP_GLSL

#include "../pn/pn_eval.glsl"

layout(std140, SFFD_SET binding = SFFD_BINDING_PARAMS) uniform ClipBlock { ClipParams params; };
// Two input ranges of sections (layout.h, ClipParams.sections and .words), within ES 3.1's 4 storage
// blocks with the two outputs; clip_count writes the counts' section, so there the uint range is not
// read-only.
layout(std430, SFFD_SET binding = SFFD_BINDING_CLIP_REALS) readonly buffer ClipInReals { real4 clipInReals[]; };
#ifdef SFFD_CLIP_WRITES_COUNTS
layout(std430, SFFD_SET binding = SFFD_BINDING_CLIP_WORDS) buffer ClipInWords { uint clipInWords[]; };
#else
layout(std430, SFFD_SET binding = SFFD_BINDING_CLIP_WORDS) readonly buffer ClipInWords { uint clipInWords[]; };
#endif
// Where each input lies in the range (layout.h ClipParams); loadParent reads by these indices.
#define positionIndex(i) (i)
#define normalIndex(i) (params.range.z + (i))
#define pnIndex(i) (params.sections.y + (i))
#define positions(i) clipInReals[positionIndex(i)]
#define normals(i) clipInReals[normalIndex(i)]
#define slotNormals(i) clipInReals[params.sections.x + (i)]
#define pn(i) clipInReals[pnIndex(i)]
#define clipReals(i) clipInReals[params.sections.z + (i)]
#define splitTable(i) clipInWords[i]
#define counts(i) clipInWords[params.words.z + (i)]
// Four words (rolled where the host asks for it, see loadParent).
uvec4 clipWords4(uint w) {
  uvec4 r;
  if (!sffdRollsLoops()) r = uvec4(clipInWords[w], clipInWords[w + 1u], clipInWords[w + 2u], clipInWords[w + 3u]);
  else
    for (uint i = 0u; i < sffdRolled(4u); ++i) r = uvec4(r.yzw, clipInWords[w + i]);
  return r;
}
// Eight words: two records of four, in one loop where the host asks for rolled loops.
void clipWords8(uint w, out uvec4 a, out uvec4 b) {
  if (!sffdRollsLoops()) {
    a = clipWords4(w);
    b = clipWords4(w + 4u);
  } else {
    for (uint i = 0u; i < sffdRolled(8u); ++i) {
      a = uvec4(a.yzw, b.x);
      b = uvec4(b.yzw, clipInWords[w + i]);
    }
  }
}
#define triangles(i) clipWords4(params.words.x + 4u * (i))
#define clipHeaders(i) clipWords4(params.words.y + 4u * (i))
#define triangleRecords(i, verts, welds) clipWords8(params.words.x + 4u * SFFD_MESH_TRIANGLE_STRIDE * (i), verts, welds)
#define clipHeaderRecords(i, h, welds) clipWords8(params.words.y + 4u * SFFD_CLIP_HEADER_STRIDE * (i), h, welds)

// The split of one clip triangle: counts, the canonical-to-local corner map and the pattern entry.
struct ClipSetup {
  // Vectors, not arrays: a vector's component picked by a variable is a select, an array's element a
  // memory access (one per lane on lavapipe 22.3).
  uvec3 perm;        // canonical corner m -> local corner
  bool odd;          // the map reverses the winding
  uvec3 count;       // segments of canonical edges C0C1, C1C2, C2C0
  uvec4 entry;       // firstVertex, vertexCount, firstTriangle, triangleCount
};

// From the clip triangle's corner welds and flat corners.
ClipSetup clipSetupOf(uvec4 welds, real3 corner[3]) {
  uint n[3];
  uint nmax = params.table.x;
  for (uint e = 0u; e < 3u; ++e) {
    uint a = e, b = (e + 1u) % 3u;
    if (welds[b] < welds[a]) { uint x = a; a = b; b = x; }
    P real3 d = corner[b] - corner[a];
    P real len = ssqrt(sdot(d, d));
    P real q = sdiv(len, real(params.target.x));
    real segs = ceil(q);
    // clamp() is not told what to do with a NaN (0 / 0 where a target underflowed): one segment.
    n[e] = segs > real(1) ? uint(min(segs, real(nmax))) : 1u;
  }
  // Sort the edges by (count, index): a-edge, b-edge, c-edge.
  uint ord[3] = uint[3](0u, 1u, 2u);
  for (uint i = 0u; i < 2u; ++i)
    for (uint j = 0u; j < 2u - i; ++j) {
      uint x = ord[j], y = ord[j + 1u];
      if (n[y] < n[x] || (n[y] == n[x] && y < x)) { ord[j] = y; ord[j + 1u] = x; }
    }
  ClipSetup S;
  uint ea = ord[0], eb = ord[1];
  if (eb == (ea + 1u) % 3u) {   // C0 C1 C2 = ea, ea+1, ea+2: a rotation
    S.perm[0] = ea; S.perm[1] = (ea + 1u) % 3u; S.perm[2] = (ea + 2u) % 3u; S.odd = false;
  } else {                      // C1 is the start of the a-edge: a reflection
    S.perm[0] = (ea + 1u) % 3u; S.perm[1] = ea; S.perm[2] = (ea + 2u) % 3u; S.odd = true;
  }
  S.count[0] = n[ord[0]];
  S.count[1] = n[ord[1]];
  S.count[2] = n[ord[2]];
  // Float lengths of a flat triangle may break a + b >= c by one segment: fall back to c = a + b.
  uint cc = min(S.count[2], S.count[0] + S.count[1]);
  uint key = ((S.count[0] - 1u) * nmax + (S.count[1] - 1u)) * nmax + (cc - 1u);
  S.entry = clipWords4(4u * key);   // splitTable(4 key ..)
  return S;
}

ClipSetup clipSetup(uint ct) {
  uvec4 welds = clipHeaders(SFFD_CLIP_HEADER_STRIDE * ct + 1u);
  real3 corner[3];   // rolled where the host asks for it (see loadParent)
  if (!sffdRollsLoops()) {
    for (uint c = 0u; c < 3u; ++c) corner[c] = clipReals(SFFD_CLIP_REAL_STRIDE * ct + 3u + c).xyz;
  } else {
    for (uint c = 0u; c < sffdRolled(3u); ++c) {
      corner[0] = corner[1];
      corner[1] = corner[2];
      corner[2] = clipReals(SFFD_CLIP_REAL_STRIDE * ct + 3u + c).xyz;
    }
  }
  return clipSetupOf(welds, corner);
}

// Where a point lies on the parent: kind 0..2 parent corner, 3..5 on parent edge kind-3 at t (from the
// edge's lower-weld endpoint), 6 inside at lam.
struct Site {
  uint kind;
  real t;
  real3 lam;
};

struct SiteValue {
  real3 lam, xpn, xflat, nlin, npn;
};

// A parent triangle and its PN record, read once per clip triangle: on lavapipe 22.3 a storage read
// at an address that differs between lanes is a loop over the lanes, and both sides of every branch
// run under lane masks, so reads in the per-sub-triangle loop were most of clip_write's time.
struct Parent {
  uint id;      // the mesh's triangle id
  uint local;   // its entry in the bound per-parent sections (ClipParams.range.w)
  uvec4 verts, welds;
  real3 V[3], N[3];
  real3 b[10];  // the PN control points, in the linear index order
  real3 n[6];   // the PN normal control points
};

// The reads in two forms (prelude.glsl sffdRollsLoops): for Mesa 22.3 and GPUs, few iterations of
// several reads; where the host asks for rolled loops, one read an iteration. The values go through a
// shift register (an array indexed by constants only: registers). Same values, same bits.
// Without `withPn` the PN record is not read and its points are 0: for a clip triangle whose sites are
// all parent corners (cornerSitesOnly). The reads are in a branch, which lavapipe 25.0 skips where no lane
// takes it and in which 22.3 reads for the lanes that take it only (docs/performance/kernels.md, "Reads
// that a clip triangle needs").
Parent loadParent(uint id, bool withPn) {
  Parent p;
  p.id = id;
  p.local = id - params.range.w;
  triangleRecords(p.local, p.verts, p.welds);
  // 0..2 positions, 3..5 normals, 6..21 the PN record (10 control points, 6 normal control points):
  // two iterations of eleven reads.
  real3 q[22];
  uint base = SFFD_PN_STRIDE * p.local;
  for (uint j = 6u; j < 22u; ++j) q[j] = real3(0);   // the PN record's, where it is not read
  if (!sffdRollsLoops()) {
    for (uint i = 0u; i < 6u; ++i) q[i] = clipInReals[i < 3u ? positionIndex(p.verts[i]) : normalIndex(p.verts[i - 3u])].xyz;
    if (withPn)
      for (uint h = 0u; h < 2u; ++h) {   // two iterations of eight reads
        for (uint j = 0u; j < 8u; ++j) q[6u + j] = q[14u + j];
        for (uint j = 0u; j < 8u; ++j) q[14u + j] = clipInReals[pnIndex(base + 8u * h + j)].xyz;
      }
  } else {
    // Three loops, each with a shift register of its own (6, 10, 6): every iteration moves each element of
    // its register under the lane mask, so one register of 22 cost 21 moves a read, these 5 to 9
    // (clip_write on Mesa 25.0: 76.2 -> 70.4 M instructions a teapot run, callgrind).
    for (uint i = 0u; i < sffdRolled(6u); ++i) {
      uint a = i < 3u ? positionIndex(p.verts[i % 3u]) : normalIndex(p.verts[i % 3u]);
      for (uint j = 0u; j < 5u; ++j) q[j] = q[j + 1u];
      q[5] = clipInReals[a].xyz;
    }
    if (withPn) {
      for (uint i = 0u; i < sffdRolled(10u); ++i) {
        for (uint j = 6u; j < 15u; ++j) q[j] = q[j + 1u];
        q[15] = clipInReals[pnIndex(base + i)].xyz;
      }
      for (uint i = 0u; i < sffdRolled(6u); ++i) {
        for (uint j = 16u; j < 21u; ++j) q[j] = q[j + 1u];
        q[21] = clipInReals[pnIndex(base + 10u + i)].xyz;
      }
    }
  }
  p.V[0] = q[0]; p.V[1] = q[1]; p.V[2] = q[2];
  p.N[0] = q[3]; p.N[1] = q[4]; p.N[2] = q[5];
  for (uint i = 0u; i < 10u; ++i) p.b[i] = q[6u + i];
  for (uint i = 0u; i < 6u; ++i) p.n[i] = q[16u + i];
  return p;
}

// The edge control point of slot s and the normal control point of edge e (1, 4, 2), picked from the
// registers by selects.
real3 slotCp(Parent p, uint s) {
  uint i = kSlotCp(s);
  return i == 1u ? p.b[1] : (i == 2u ? p.b[2] : (i == 3u ? p.b[3] : (i == 5u ? p.b[5] : (i == 7u ? p.b[7] : p.b[8]))));
}
real3 edgeNormalCp(Parent p, uint e) { return e == 0u ? p.n[1] : (e == 1u ? p.n[4] : p.n[2]); }

// Corner c's position and normal, and the unit barycentric of corner c: selects, not a local array
// indexed by a variable (kept in memory on lavapipe, and much code to generate on Mesa 25.0).
real3 parentV(Parent p, uint c) { return c == 0u ? p.V[0] : (c == 1u ? p.V[1] : p.V[2]); }
real3 parentN(Parent p, uint c) { return c == 0u ? p.N[0] : (c == 1u ? p.N[1] : p.N[2]); }
// (a at corner ca, b at corner cb, 0 at the third), ca != cb.
real3 twoCornerLam(uint ca, real a, uint cb, real b) {
  return real3(ca == 0u ? a : (cb == 0u ? b : real(0)), ca == 1u ? a : (cb == 1u ? b : real(0)),
               ca == 2u ? a : (cb == 2u ? b : real(0)));
}

// Corners of parent edge e ordered by weld id.
void edgeEnds(Parent p, uint e, out uint lo, out uint hi) {
  lo = e;
  hi = (e + 1u) % 3u;
  if (p.welds[hi] < p.welds[lo]) { uint x = lo; lo = hi; hi = x; }
}

uint slotOf(uint corner, uint e) { return corner == e ? 2u * corner + 1u : 2u * corner; }

SiteValue evaluateSite(Parent p, Site s) {
  SiteValue r;
  if (s.kind < 3u) {
    uint k = s.kind;
    r.lam = real3(k == 0u ? real(1) : real(0), k == 1u ? real(1) : real(0), k == 2u ? real(1) : real(0));
    r.xpn = parentV(p, k);
    r.xflat = r.xpn;
    r.nlin = parentN(p, k);
    r.npn = r.nlin;
  } else if (s.kind < 6u) {
    uint e = s.kind - 3u, lo, hi;
    edgeEnds(p, e, lo, hi);
    P real t = s.t;
    P real u = real(1) - t;
    r.lam = twoCornerLam(lo, u, hi, t);
    real3 vLo = parentV(p, lo), vHi = parentV(p, hi), nLo = parentN(p, lo), nHi = parentN(p, hi);
    r.xpn = pnEdgeCurve(vLo, slotCp(p, slotOf(lo, e)), slotCp(p, slotOf(hi, e)), vHi, t);
    P real3 xf = vLo + (vHi - vLo) * t;
    r.xflat = xf;
    P real3 nl = nLo * u + nHi * t;
    r.nlin = snormalize(nl);
    r.npn = pnEdgeNormalCurve(nLo, edgeNormalCp(p, e), nHi, t);
  } else {
    P real3 l = s.lam;
    r.lam = l;
    real w[10];
    pnCubicWeights(l, w);
    // Sums written out in the loops' order: on Mesa 25.0 this branch took most of clip_write's 13 to
    // 17 s of machine-code generation at its first dispatch with the loops, about half that without.
    P real3 x = (((((((((real3(0) + p.b[0] * w[0]) + p.b[1] * w[1]) + p.b[2] * w[2]) + p.b[3] * w[3]) + p.b[4] * w[4]) +
                   p.b[5] * w[5]) + p.b[6] * w[6]) + p.b[7] * w[7]) + p.b[8] * w[8]) + p.b[9] * w[9];
    r.xpn = x;
    P real3 xf = (p.V[0] * l.x + p.V[1] * l.y) + p.V[2] * l.z;
    r.xflat = xf;
    P real3 nl = (p.N[0] * l.x + p.N[1] * l.y) + p.N[2] * l.z;
    r.nlin = snormalize(nl);
    real q[6];
    pnQuadraticWeights(l, q);
    P real3 nn = (((((real3(0) + p.n[0] * q[0]) + p.n[1] * q[1]) + p.n[2] * q[2]) + p.n[3] * q[3]) + p.n[4] * q[4]) + p.n[5] * q[5];
    r.npn = snormalize(nn);
  }
  return r;
}

// Parameter of a site along parent edge e (the site lies on it), from the edge's lower-weld endpoint.
real siteParamOnEdge(Parent p, uint kind, real t, uint e) {
  uint lo, hi;
  edgeEnds(p, e, lo, hi);
  return kind < 3u ? (kind == lo ? real(0) : real(1)) : t;
}

// The neighbouring triangle's PN normal along one parent edge, where the edge is a crease: its normals
// at the edge's ends are in this triangle's slot records.
struct EdgeNeighbour {
  bool crease;
  uint e;                 // the parent edge
  real3 nLo, nMid, nHi;   // the neighbour's quadratic normal curve, from the edge's lower-weld end
};

EdgeNeighbour edgeNeighbour(Parent p, real pe) {
  EdgeNeighbour r;
  r.crease = false;
  r.e = 0u;
  r.nLo = r.nMid = r.nHi = real3(0);
  if (pe < real(0)) return r;   // the clip edge is not on a parent edge
  uint e = uint(pe), lo, hi;
  edgeEnds(p, e, lo, hi);
  uint sLo = SFFD_SLOT_NORMAL_STRIDE * p.local + 2u * slotOf(lo, e);
  uint sHi = SFFD_SLOT_NORMAL_STRIDE * p.local + 2u * slotOf(hi, e);
  r.e = e;
  // The flags first, one word each: most edges are no crease, and their four normals are then not read
  // (as the PN record in loadParent).
  r.crease = !(slotNormals(sLo).w < real(0.5) && slotNormals(sHi).w < real(0.5));
  if (!r.crease) return r;
  real4 fLo, gLo, fHi, gHi;   // rolled where the host asks for it (see loadParent)
  if (!sffdRollsLoops()) {
    fLo = slotNormals(sLo), gLo = slotNormals(sLo + 1u);
    fHi = slotNormals(sHi), gHi = slotNormals(sHi + 1u);
  } else {
    real4 q[4];
    for (uint i = 0u; i < sffdRolled(4u); ++i) {
      for (uint j = 0u; j < 3u; ++j) q[j] = q[j + 1u];
      q[3] = slotNormals((i < 2u ? sLo : sHi) + i % 2u);
    }
    fLo = q[0], gLo = q[1], fHi = q[2], gHi = q[3];
  }
  r.nLo = gLo.w > real(0.5) ? gLo.xyz : fLo.xyz;   // the one that is not this triangle's own
  r.nHi = gHi.w > real(0.5) ? gHi.xyz : fHi.xyz;
  r.nMid = pnEdgeNormal(parentV(p, lo), parentV(p, hi), r.nLo, r.nHi);
  return r;
}

// The neighbour's normal at parameter t of the edge. At the edge's ends it is its vertex normal itself,
// bit for bit, as the neighbour's own records hold it there.
real3 neighbourNormalAt(EdgeNeighbour n, real t) {
  if (t == real(0)) return n.nLo;
  if (t == real(1)) return n.nHi;
  return pnEdgeNormalCurve(n.nLo, n.nMid, n.nHi, t);
}

// A clip triangle's corners and edges, read once (as Parent): per corner its barycentrics in the
// parent (w: the parameter t on a parent edge) and site kind, per clip edge the parent edge it lies on
// (x, -1 if none) and the parameters of its ends there (y, z).
// Where the host asks for rolled loops, also its flat corners, for clipSetupOf: every record of the
// clip triangle read once, one an iteration (see loadParent).
struct ClipTriangle {
  uint parent, kinds;
  uvec4 welds;
  real4 lam[3], edgeParams[3];
  real3 flatCorner[3];
};

ClipTriangle loadClipTriangle(uint ct) {
  ClipTriangle T;
  uvec4 h;
  clipHeaderRecords(ct, h, T.welds);
  T.parent = h.x;
  T.kinds = h.y;
  uint base = SFFD_CLIP_REAL_STRIDE * ct;
  if (!sffdRollsLoops()) {
    real4 q[6];   // corners 0..2, then edge params 6..8: two iterations of three reads
    for (uint h = 0u; h < 2u; ++h) {
      for (uint j = 0u; j < 3u; ++j) q[j] = q[j + 3u];
      for (uint j = 0u; j < 3u; ++j) q[3u + j] = clipReals(base + 6u * h + j);
    }
    T.lam[0] = q[0]; T.lam[1] = q[1]; T.lam[2] = q[2];
    T.edgeParams[0] = q[3]; T.edgeParams[1] = q[4]; T.edgeParams[2] = q[5];
  } else {
    real4 q[9];   // corners 0..2, flat corners 3..5, edge params 6..8
    for (uint i = 0u; i < sffdRolled(9u); ++i) {
      for (uint j = 0u; j < 8u; ++j) q[j] = q[j + 1u];
      q[8] = clipReals(base + i);
    }
    T.lam[0] = q[0]; T.lam[1] = q[1]; T.lam[2] = q[2];
    T.flatCorner[0] = q[3].xyz; T.flatCorner[1] = q[4].xyz; T.flatCorner[2] = q[5].xyz;
    T.edgeParams[0] = q[6]; T.edgeParams[1] = q[7]; T.edgeParams[2] = q[8];
  }
  return T;
}

real4 cornerLam(ClipTriangle T, uint c) { return c == 0u ? T.lam[0] : (c == 1u ? T.lam[1] : T.lam[2]); }
real4 clipEdgeParams(ClipTriangle T, uint e) { return e == 0u ? T.edgeParams[0] : (e == 1u ? T.edgeParams[1] : T.edgeParams[2]); }

// Whether every site of the clip triangle's split is a corner of its parent: one sub-triangle (each
// edge one segment) whose corners are parent corners, as every clip triangle is where the mesh is finer
// than the edge length. Its sites' values are then the parent's corner positions and normals alone.
bool cornerSitesOnly(ClipTriangle T, ClipSetup S) {
  return S.count == uvec3(1u) && (T.kinds & 255u) < 3u && ((T.kinds >> 8u) & 255u) < 3u && ((T.kinds >> 16u) & 255u) < 3u;
}

// Site of a corner of the clip triangle.
Site clipCornerSite(ClipTriangle T, uint c) {
  Site s;
  s.kind = (T.kinds >> (8u * c)) & 255u;
  real4 l = cornerLam(T, c);
  s.lam = l.xyz;
  s.t = l.w;
  return s;
}

// Site of a pattern vertex of the clip triangle. `edge`/`step` come from the table.
Site patternSite(ClipTriangle T, ClipSetup S, uint edge, uint step, real3 lamCanon) {
  if (edge < 3u && step == 0u) return clipCornerSite(T, S.perm[edge]);
  real3 lamLocal = real3(0);
  lamLocal = withComponent(lamLocal, S.perm[0], lamCanon.x);
  lamLocal = withComponent(lamLocal, S.perm[1], lamCanon.y);
  lamLocal = withComponent(lamLocal, S.perm[2], lamCanon.z);
  if (edge < 3u) {
    // On clip edge between local corners a and b: the parameter from the lower-weld end is that
    // end's partner's weight, bit-identical from both sides (the table's symmetric pairs).
    uint a = S.perm[edge], b = S.perm[(edge + 1u) % 3u];
    uint lo = T.welds[a] <= T.welds[b] ? a : b, hi = lo == a ? b : a;
    P real tl = componentOf(lamLocal, hi);
    uint ce = (b == (a + 1u) % 3u) ? a : b;   // local clip edge index (corner ce -> ce+1)
    real4 ep = clipEdgeParams(T, ce);
    Site s;
    if (ep.x >= real(0)) {
      real tLo = lo == ce ? ep.y : ep.z, tHi = lo == ce ? ep.z : ep.y;
      s.kind = 3u + uint(ep.x);
      P real tt = tLo + (tHi - tLo) * tl;
      s.t = tt;
      s.lam = real3(0);
    } else {
      real3 lamLo = cornerLam(T, lo).xyz, lamHi = cornerLam(T, hi).xyz;
      s.kind = 6u;
      s.t = real(0);
      P real3 lm = lamLo + (lamHi - lamLo) * tl;
      s.lam = lm;
    }
    return s;
  }
  Site s;
  s.kind = 6u;
  s.t = real(0);
  P real3 lm = (T.lam[0].xyz * lamLocal.x + T.lam[1].xyz * lamLocal.y) + T.lam[2].xyz * lamLocal.z;
  s.lam = lm;
  return s;
}

// The canonical edge two pattern vertices share (3: none).
uint sharedCanonicalEdge(uint ea, uint ja, uint eb, uint jb) {
  if (ea > 2u || eb > 2u) return 3u;
  if (ea == eb) return ea;
  if (ja == 0u && eb == (ea + 2u) % 3u) return eb;   // a is corner C_ea, the end of edge ea-1
  if (jb == 0u && ea == (eb + 2u) % 3u) return ea;
  return 3u;
}

#endif
