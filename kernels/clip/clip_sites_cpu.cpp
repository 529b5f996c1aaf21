// The CPU entries of kernels clip_count and clip_write: ClipTwin is the C++ twin of clip_sites.glsl
// (its site evaluation is clip_sites.h), reading the bound ranges as the kernels do.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <span>

#include "kernels/clip/clip_sites.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/common/cpu_kernel.h"

namespace sffd {
namespace {

template <class Real>
struct ClipTwin {
  const CpuKernelArgs& args;
  const gpu::ClipParams& params;
  std::span<const uint32_t> words, meshTriangles;
  std::span<const Real> positions, normals, slots, pn;
  const Real* clipReals;
  const uint32_t* clipHeaders;
  Real l;

  // The two input ranges' sections (layout.h, ClipParams), as clip_sites.glsl reads them.
  ClipTwin(const CpuKernelArgs& a, uint64_t clipTriangles)
      : args(a),
        params(a.paramsAs<gpu::ClipParams>()),
        words(a.array<const uint32_t>(SFFD_BINDING_CLIP_WORDS)),
        meshTriangles(from(words, params.words.x)),
        positions(a.array<const Real>(SFFD_BINDING_CLIP_REALS)),
        normals(from(positions, 4 * uint64_t(params.range.z))),
        slots(from(positions, 4 * uint64_t(params.sections.x))),
        pn(from(positions, 4 * uint64_t(params.sections.y))),
        clipReals(a.array<const Real>(SFFD_BINDING_CLIP_REALS, 4 * (uint64_t(params.sections.z) + SFFD_CLIP_REAL_STRIDE * clipTriangles))
                      .data() + 4 * uint64_t(params.sections.z)),
        clipHeaders(a.array<const uint32_t>(SFFD_BINDING_CLIP_WORDS, params.words.y + 4 * SFFD_CLIP_HEADER_STRIDE * clipTriangles)
                        .data() + params.words.y),
        l(Real(params.target.x)) {}

  template <class T>
  static std::span<const T> from(std::span<const T> s, uint64_t first) { return s.subspan(std::min<uint64_t>(s.size(), first)); }

  static RVec3<Real> v3(const Real* a, size_t i) { return {a[4 * i], a[4 * i + 1], a[4 * i + 2]}; }

  struct Setup {
    int perm[3];
    bool odd;
    uint32_t count[3];
    uint32_t entry[4];
  };

  Setup setup(size_t ct) const {
    const uint32_t* welds = &clipHeaders[8 * ct + 4];
    RVec3<Real> corner[3];
    for (int c = 0; c < 3; ++c) corner[c] = v3(clipReals, SFFD_CLIP_REAL_STRIDE * ct + 3 + c);
    uint32_t n[3], nmax = params.table.x;
    for (int e = 0; e < 3; ++e) {
      int a = e, b = (e + 1) % 3;
      if (welds[b] < welds[a]) std::swap(a, b);
      RVec3<Real> d = corner[b] - corner[a];
      Real len = std::sqrt(sdot(d, d));
      Real q = len / l;
      Real segs = std::ceil(q);
      n[e] = segs > Real(1) ? uint32_t(std::min(segs, Real(nmax))) : 1;   // as the kernel: a NaN is one segment
    }
    int ord[3] = {0, 1, 2};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2 - i; ++j) {
        int x = ord[j], y = ord[j + 1];
        if (n[y] < n[x] || (n[y] == n[x] && y < x)) ord[j] = y, ord[j + 1] = x;
      }
    Setup S;
    int ea = ord[0], eb = ord[1];
    if (eb == (ea + 1) % 3) S.perm[0] = ea, S.perm[1] = (ea + 1) % 3, S.perm[2] = (ea + 2) % 3, S.odd = false;
    else S.perm[0] = (ea + 1) % 3, S.perm[1] = ea, S.perm[2] = (ea + 2) % 3, S.odd = true;
    for (int i = 0; i < 3; ++i) S.count[i] = n[ord[i]];
    uint32_t cc = std::min(S.count[2], S.count[0] + S.count[1]);
    uint32_t key = ((S.count[0] - 1) * nmax + (S.count[1] - 1)) * nmax + (cc - 1);
    args.check(4 * uint64_t(key) + 4 <= words.size(), "a split pattern is outside the table");
    for (int i = 0; i < 4; ++i) S.entry[i] = words[4 * key + i];
    return S;
  }

  ParentT<Real> parent(uint32_t id) const {
    ParentT<Real> p;
    p.id = id;
    const uint64_t local = uint64_t(id) - params.range.w;   // the entry in the bound per-parent sections
    args.check(id >= params.range.w && 8 * (local + 1) <= meshTriangles.size() && 4 * SFFD_PN_STRIDE * (local + 1) <= pn.size() &&
                   4 * SFFD_SLOT_NORMAL_STRIDE * (local + 1) <= slots.size(),
               "a clip triangle's parent is outside the mesh buffers");
    for (int c = 0; c < 3; ++c) {
      p.verts[c] = meshTriangles[8 * local + c];
      p.welds[c] = meshTriangles[8 * local + 4 + c];
      args.check(4 * (uint64_t(p.verts[c]) + 1) <= std::min(positions.size(), normals.size()),
                 "a triangle's vertex id is outside the vertex buffers");
      p.V[c] = v3(positions.data(), p.verts[c]);
      p.N[c] = v3(normals.data(), p.verts[c]);
    }
    p.pn = &pn[local * SFFD_PN_STRIDE * 4];
    p.slot = &slots[local * SFFD_SLOT_NORMAL_STRIDE * 4];
    return p;
  }

  SiteT<Real> cornerSite(size_t ct, int c) const {
    SiteT<Real> s;
    s.kind = (clipHeaders[8 * ct + 1] >> (8 * c)) & 255u;
    size_t i = SFFD_CLIP_REAL_STRIDE * ct + c;
    s.lam = v3(clipReals, i);
    s.t = clipReals[4 * i + 3];
    return s;
  }

  SiteT<Real> patternSite(size_t ct, const Setup& S, uint32_t edge, uint32_t step, RVec3<Real> lamCanon) const {
    if (edge < 3 && step == 0) return cornerSite(ct, S.perm[edge]);
    RVec3<Real> lamLocal;
    lamLocal[S.perm[0]] = lamCanon.x;
    lamLocal[S.perm[1]] = lamCanon.y;
    lamLocal[S.perm[2]] = lamCanon.z;
    size_t base = SFFD_CLIP_REAL_STRIDE * ct;
    SiteT<Real> s;
    if (edge < 3) {
      int a = S.perm[edge], b = S.perm[(edge + 1) % 3];
      const uint32_t* welds = &clipHeaders[8 * ct + 4];
      int lo = welds[a] <= welds[b] ? a : b, hi = lo == a ? b : a;
      Real tl = lamLocal[hi];
      int ce = (b == (a + 1) % 3) ? a : b;
      const Real* ep = &clipReals[4 * (base + 6 + ce)];
      if (ep[0] >= Real(0)) {
        Real tLo = lo == ce ? ep[1] : ep[2], tHi = lo == ce ? ep[2] : ep[1];
        s.kind = 3 + uint32_t(ep[0]);
        s.t = tLo + (tHi - tLo) * tl;
        s.lam = {};
      } else {
        RVec3<Real> lamLo = v3(clipReals, base + lo), lamHi = v3(clipReals, base + hi);
        s.kind = 6;
        s.t = 0;
        s.lam = lamLo + (lamHi - lamLo) * tl;
      }
      return s;
    }
    s.kind = 6;
    s.t = 0;
    s.lam = (v3(clipReals, base) * lamLocal.x + v3(clipReals, base + 1) * lamLocal.y) + v3(clipReals, base + 2) * lamLocal.z;
    return s;
  }

  static uint32_t sharedCanonicalEdge(uint32_t ea, uint32_t ja, uint32_t eb, uint32_t jb) {
    if (ea > 2 || eb > 2) return 3;
    if (ea == eb) return ea;
    if (ja == 0 && eb == (ea + 2) % 3) return eb;
    if (jb == 0 && ea == (eb + 2) % 3) return ea;
    return 3;
  }

  // clip_write for clip triangle ct: its sub-triangles from `out0` of the bound output ranges.
  void write(size_t ct, const Setup& S, size_t out0, uint32_t* headers, Real* records) const {
    ParentT<Real> par = parent(clipHeaders[8 * ct]);
    for (uint32_t k = 0; k < S.entry[3]; ++k) {
      uint32_t idx[3], edge[3], step[3];
      for (int c = 0; c < 3; ++c) {
        uint32_t i = 3 * (S.entry[2] + k) + c;
        args.check(params.table.z + uint64_t(i / 2) < words.size(), "a pattern triangle is outside the table");
        uint32_t word = words[params.table.z + i / 2];
        idx[c] = (i % 2 == 0) ? (word & 65535u) : (word >> 16);
      }
      if (S.odd) std::swap(idx[1], idx[2]);
      SiteT<Real> site[3];
      SiteValueT<Real> val[3];
      for (int c = 0; c < 3; ++c) {
        size_t v = params.table.y + 4 * (size_t(S.entry[0]) + idx[c]);
        args.check(v + 4 <= words.size(), "a pattern vertex is outside the table");
        float lf[3];
        std::memcpy(lf, &words[v], 12);
        uint32_t w = words[v + 3];
        edge[c] = w & 255u;
        step[c] = w >> 16;
        site[c] = patternSite(ct, S, edge[c], step[c], RVec3<Real>{Real(lf[0]), Real(lf[1]), Real(lf[2])});
        val[c] = par.evaluate(site[c]);
      }
      size_t o = out0 + k;
      auto parentEdgeOf = [&](int c, int d) {
        uint32_t ce = sharedCanonicalEdge(edge[c], step[c], edge[d], step[d]);
        if (ce >= 3) return -1;
        int a = S.perm[ce], b = S.perm[(ce + 1) % 3];
        int le = (b == (a + 1) % 3) ? a : b;
        Real pe = clipReals[4 * (SFFD_CLIP_REAL_STRIDE * ct + 6 + le)];
        return pe >= Real(0) ? int(pe) : -1;
      };
      storeSubTriangle(par, site, val, parentEdgeOf, &records[o * SFFD_SUB_STRIDE * 4], &headers[4 * o]);
    }
  }
};

template <class Real>
void countThreads(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  const auto& p = a.paramsAs<gpu::ClipParams>();
  const uint64_t n = uint64_t(p.range.x) + p.range.y;
  ClipTwin<Real> C(a, n);
  uint32_t* counts = a.array<uint32_t>(SFFD_BINDING_CLIP_WORDS, p.words.z + n).data() + p.words.z;
  for (uint64_t t = first; t < std::min<uint64_t>(last, p.range.y); ++t) {
    const size_t ct = p.range.x + uint32_t(t);
    counts[ct] = C.setup(ct).entry[3];
  }
}

template <class Real>
void writeThreads(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  const auto& p = a.paramsAs<gpu::ClipParams>();
  const uint64_t n = uint64_t(p.range.x) + p.range.y;
  ClipTwin<Real> C(a, n);
  const uint32_t* offsets = a.array<const uint32_t>(SFFD_BINDING_CLIP_WORDS, p.words.z + n).data() + p.words.z;
  std::span<uint32_t> headers = a.array<uint32_t>(SFFD_BINDING_SUB_HEADERS);
  std::span<Real> records = a.array<Real>(SFFD_BINDING_SUB_RECORDS);
  const uint64_t capacity = std::min<uint64_t>(headers.size() / 4, records.size() / (4 * SFFD_SUB_STRIDE));
  for (uint64_t t = first; t < std::min<uint64_t>(last, p.range.y); ++t) {
    const size_t ct = p.range.x + uint32_t(t);
    const typename ClipTwin<Real>::Setup S = C.setup(ct);
    a.check(uint64_t(offsets[ct]) + S.entry[3] <= capacity, "sub-triangles past the end of the output ranges");
    C.write(ct, S, offsets[ct], headers.data(), records.data());
  }
}

}  // namespace

void cpu::clipCount(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  a.variant.f64 ? countThreads<double>(a, first, last) : withAvx2<countThreads<float>>(a, first, last);
}

void cpu::clipWrite(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  a.variant.f64 ? writeThreads<double>(a, first, last) : withAvx2<writeThreads<float>>(a, first, last);
}

}  // namespace sffd
