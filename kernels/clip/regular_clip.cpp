#include "kernels/clip/regular_clip.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <stdexcept>

#include "kernels/clip/clip_sites.h"
#include <sffd/error.h>
#include "model/lattice_pack.h"
#include "kernels/clip/split_pattern_table.h"
#include "core/huge_pages.h"
#include "core/wall_clock.h"

namespace sffd {
namespace {

// ---------------------------------------------------------------- pre-split into clip triangles

int segmentCount(const glm::dvec3& a, const glm::dvec3& b, double l) {
  double q = glm::length(b - a) / l;
  return q > 1e9 ? 1000000000 : int(std::max(1.0, std::ceil(q)));
}

struct SplitPoint {
  uint32_t weld;
  glm::dvec3 flat;
};

ClipTriangle parentClipTriangle(const Mesh& mesh, uint32_t t) {
  ClipTriangle c;
  c.parent = t;
  for (int k = 0; k < 3; ++k) {
    uint32_t v = mesh.triangles[t][k];
    c.weld[k] = mesh.weldId[v];
    c.flat[k] = mesh.positions[v];
    c.corners[k].kind = SubVertexKind(k);
    c.corners[k].lam = glm::dvec3(0);
    c.corners[k].lam[k] = 1;
  }
  for (int e = 0; e < 3; ++e) {
    c.parentEdge[e] = e;
    bool startIsLo = c.weld[e] <= c.weld[(e + 1) % 3];
    c.edgeParam[e] = startIsLo ? std::array<double, 2>{0, 1} : std::array<double, 2>{1, 0};
  }
  return c;
}

// Bisects clip edge e of c at its split point; returns the two children (same winding).
std::array<ClipTriangle, 2> bisect(const Mesh& mesh, const ClipTriangle& c, int e, const SplitPoint& sp) {
  int a = e, b = (e + 1) % 3, o = (e + 2) % 3;
  SubVertex mid;
  double tMid = 0;
  if (c.parentEdge[e] >= 0) {
    int pe = c.parentEdge[e];
    tMid = 0.5 * (c.edgeParam[e][0] + c.edgeParam[e][1]);
    const auto& tri = mesh.triangles[c.parent];
    int lo = pe, hi = (pe + 1) % 3;
    if (mesh.weldId[tri[hi]] < mesh.weldId[tri[lo]]) std::swap(lo, hi);
    mid.kind = SubVertexKind(3 + pe);
    mid.t = tMid;
    mid.lam = glm::dvec3(0);
    mid.lam[lo] = 1 - tMid;
    mid.lam[hi] = tMid;
  } else {
    mid.kind = SubVertexKind::Interior;
    mid.lam = 0.5 * (c.corners[a].lam + c.corners[b].lam);
  }
  // Child 0: (a, mid, o); child 1: (mid, b, o).
  ClipTriangle c0 = c, c1 = c;
  c0.weld = {c.weld[a], sp.weld, c.weld[o]};
  c0.corners = {c.corners[a], mid, c.corners[o]};
  c0.flat = {c.flat[a], sp.flat, c.flat[o]};
  c0.parentEdge = {c.parentEdge[e], -1, c.parentEdge[o]};
  c0.edgeParam = {std::array<double, 2>{c.edgeParam[e][0], tMid}, std::array<double, 2>{0, 0}, c.edgeParam[o]};
  c1.weld = {sp.weld, c.weld[b], c.weld[o]};
  c1.corners = {mid, c.corners[b], c.corners[o]};
  c1.flat = {sp.flat, c.flat[b], c.flat[o]};
  c1.parentEdge = {c.parentEdge[e], c.parentEdge[b], -1};
  c1.edgeParam = {std::array<double, 2>{tMid, c.edgeParam[e][1]}, c.edgeParam[b], std::array<double, 2>{0, 0}};
  return {c0, c1};
}

}  // namespace

struct ClipTriangleBuilder::Splits {
  std::map<std::pair<uint32_t, uint32_t>, SplitPoint> points;   // by the clip edge's weld pair
};

ClipTriangleBuilder::ClipTriangleBuilder(const Mesh& mesh, double l, int nmax)
    : mesh_(mesh), l_(l), nmax_(nmax), splits_(std::make_unique<Splits>()) {
  for (uint32_t w : mesh.weldId) nextWeld_ = std::max(nextWeld_, w + 1);
}
ClipTriangleBuilder::~ClipTriangleBuilder() = default;

void ClipTriangleBuilder::add(uint32_t t, std::vector<ClipTriangle>& out) {
  const Mesh& mesh = mesh_;
  const int nmax = nmax_;
  std::vector<ClipTriangle>& work = work_;
  work.assign(1, parentClipTriangle(mesh, t));
  bool split = false;
  for (size_t i = 0; i < work.size();) {
    ClipTriangle& c = work[i];
    int worst = -1, worstCount = nmax;
    double worstLen = 0;
    for (int e = 0; e < 3; ++e) {
      int a = e, b = (e + 1) % 3;
      if (c.weld[b] < c.weld[a]) std::swap(a, b);
      int n = segmentCount(c.flat[a], c.flat[b], l_);
      double len = glm::length(c.flat[b] - c.flat[a]);
      if (n > worstCount || (n == worstCount && n > nmax && len > worstLen)) worst = e, worstCount = n, worstLen = len;
    }
    if (worst < 0 || made_ + work.size() > (size_t(1) << 31)) {
      ++i;
      continue;
    }
    split = true;
    uint32_t wa = c.weld[worst], wb = c.weld[(worst + 1) % 3];
    auto key = std::minmax(wa, wb);
    auto it = splits_->points.find(key);
    if (it == splits_->points.end()) {
      // The split point from the edge's lower-weld end: the neighbour finds the same point here.
      const glm::dvec3& pLo = wa <= wb ? c.flat[worst] : c.flat[(worst + 1) % 3];
      const glm::dvec3& pHi = wa <= wb ? c.flat[(worst + 1) % 3] : c.flat[worst];
      it = splits_->points.emplace(key, SplitPoint{nextWeld_++, pLo + (pHi - pLo) * 0.5}).first;
    }
    auto kids = bisect(mesh, c, worst, it->second);
    work[i] = kids[0];
    work.push_back(kids[1]);
  }
  if (split) ++presplitParents_;
  made_ += work.size();
  out.insert(out.end(), work.begin(), work.end());
}

ClipTriangles buildClipTriangles(const Mesh& mesh, double l, int nmax) {
  ClipTriangles out;
  ClipTriangleBuilder builder(mesh, l, nmax);
  reserveHuge(out.triangles, mesh.triangles.size());   // at least one a parent: no growth copies below that
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t) builder.add(t, out.triangles);
  out.presplitParents = builder.presplitParents();
  return out;
}

// ---------------------------------------------------------------- packed inputs of the clip kernels

PackedClip packClip(const ClipTriangles& clip) { return packClip(clip, 0, clip.triangles.size()); }

PackedClip packClip(const ClipTriangles& clip, size_t first, size_t last) {
  PackedClip P;
  size_t n = last - first;
  resizeHuge(P.headers, 8 * n, 0u);
  resizeHuge(P.reals, 4 * SFFD_CLIP_REAL_STRIDE * n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const ClipTriangle& c = clip.triangles[first + i];
    uint32_t kinds = 0;
    for (int k = 0; k < 3; ++k) kinds |= uint32_t(c.corners[k].kind) << (8 * k);
    P.headers[8 * i] = c.parent;
    P.headers[8 * i + 1] = kinds;
    for (int k = 0; k < 3; ++k) P.headers[8 * i + 4 + k] = c.weld[k];
    double* r = &P.reals[4 * SFFD_CLIP_REAL_STRIDE * i];
    for (int k = 0; k < 3; ++k) {
      const SubVertex& s = c.corners[k];
      r[4 * k] = s.lam.x, r[4 * k + 1] = s.lam.y, r[4 * k + 2] = s.lam.z, r[4 * k + 3] = s.t;
      r[4 * (3 + k)] = c.flat[k].x, r[4 * (3 + k) + 1] = c.flat[k].y, r[4 * (3 + k) + 2] = c.flat[k].z;
      r[4 * (6 + k)] = c.parentEdge[k], r[4 * (6 + k) + 1] = c.edgeParam[k][0], r[4 * (6 + k) + 2] = c.edgeParam[k][1];
    }
  }
  return P;
}

// The kernels' words are the arrays' bytes (PackedTable, split_pattern_table.h) on a little-endian host.
static_assert(std::endian::native == std::endian::little, "the split-pattern table is uploaded as its bytes");
static_assert(sizeof(SplitPattern) == 16 && sizeof(SplitPatternVertex) == 16);

PackedTable packedTableOf(const SplitPatternTable& S) {
  PackedTable t;
  t.nmax = uint32_t(S.nmax());
  t.vertexWord = uint32_t(4 * S.patterns().size());
  t.triangleWord = t.vertexWord + uint32_t(4 * S.vertices().size());
  t.wordCount = t.triangleWord + uint32_t((S.triangles().size() + 1) / 2);
  return t;
}

const PackedTable& packedTable() {
  static const PackedTable T = packedTableOf(splitPatternTable());
  return T;
}

void uploadPackedTable(Backend& backend, BufferId words, const SplitPatternTable& S) {
  const PackedTable T = packedTableOf(S);
  backend.upload(words, 0, S.patterns().data(), S.patterns().size_bytes());
  backend.upload(words, uint64_t(T.vertexWord) * 4, S.vertices().data(), S.vertices().size_bytes());
  const std::span<const uint16_t> tri = S.triangles();
  const uint64_t pairs = tri.size() / 2;
  backend.upload(words, uint64_t(T.triangleWord) * 4, tri.data(), pairs * 4);
  if (tri.size() % 2) {
    const uint32_t last = tri.back();   // an odd count's last word: its upper half 0
    backend.upload(words, (uint64_t(T.triangleWord) + pairs) * 4, &last, 4);
  }
}

ClipRanges clipRanges(const PreparedMesh& mesh, size_t clipTriangles, size_t realSize) {
  return clipRanges(mesh.positions.size() / 4, 0, mesh.triangleCount(), 0, clipTriangles, realSize);
}

ClipRanges clipRanges(uint64_t vertices, uint64_t firstParent, uint64_t parents, uint64_t firstClip, uint64_t clips,
                      size_t realSize) {
  ClipRanges r;
  r.realSize = realSize;
  r.firstParent = firstParent, r.parents = parents, r.firstClip = firstClip, r.clips = clips;
  const uint64_t realAlign = SFFD_SECTION_ALIGN / (4 * realSize), wordAlign = SFFD_SECTION_ALIGN / 4;
  auto up = [](uint64_t v, uint64_t a) { return (v + a - 1) / a * a; };
  r.normals = vertices;
  r.slotNormals = up(2 * vertices, realAlign);
  r.pn = up(r.slotNormals + SFFD_SLOT_NORMAL_STRIDE * parents, realAlign);
  r.clipReals = up(r.pn + SFFD_PN_STRIDE * parents, realAlign);
  r.realElements = r.clipReals + SFFD_CLIP_REAL_STRIDE * clips;
  r.triangles = up(packedTable().wordCount, wordAlign);
  r.clipHeaders = up(r.triangles + 4 * SFFD_MESH_TRIANGLE_STRIDE * parents, wordAlign);
  r.counts = up(r.clipHeaders + 4 * SFFD_CLIP_HEADER_STRIDE * clips, wordAlign);
  r.words = r.counts + clips;
  return r;
}

void ClipRanges::name(gpu::ClipParams& p) const {
  p.range.z = uint32_t(normals);
  p.range.w = uint32_t(firstParent);
  p.sections = {uint32_t(slotNormals), uint32_t(pn), uint32_t(clipReals), 0};
  p.words = {uint32_t(triangles), uint32_t(clipHeaders), uint32_t(counts), 0};
}

template <class Real>
void writeClipVertexSection(const PreparedMesh& mesh, Real* out) {
  // positions, then normals (meshVertexRange's order), converted as they are copied: no wider copy.
  std::copy(mesh.positions.begin(), mesh.positions.end(), out);
  std::copy(mesh.normals.begin(), mesh.normals.end(), out + mesh.positions.size());
}

template <class Real>
void writeClipParentSections(const ClipRanges& r, const PreparedMesh& mesh, const std::vector<double>* pnRecords,
                             const PackedClip& clip, Real* out) {
  auto at = [&](uint64_t element) { return out + 4 * (element - r.slotNormals); };
  mesh.slotNormals(r.firstParent, r.parents, at(r.slotNormals));
  if (pnRecords) std::copy_n(pnRecords->begin() + 4 * SFFD_PN_STRIDE * r.firstParent, 4 * SFFD_PN_STRIDE * r.parents, at(r.pn));
  std::copy(clip.reals.begin(), clip.reals.end(), at(r.clipReals));
}

template <class Real>
std::vector<Real> clipRealRange(const ClipRanges& r, const PreparedMesh& mesh, const std::vector<double>* pnRecords,
                                const PackedClip& clip) {
  std::vector<Real> v;
  resizeHuge(v, 4 * r.realElements, Real(0));
  writeClipVertexSection(mesh, v.data());
  writeClipParentSections(r, mesh, pnRecords, clip, v.data() + 4 * r.slotNormals);
  return v;
}
template std::vector<float> clipRealRange<float>(const ClipRanges&, const PreparedMesh&, const std::vector<double>*, const PackedClip&);
template std::vector<double> clipRealRange<double>(const ClipRanges&, const PreparedMesh&, const std::vector<double>*, const PackedClip&);
template void writeClipVertexSection<float>(const PreparedMesh&, float*);
template void writeClipVertexSection<double>(const PreparedMesh&, double*);
template void writeClipParentSections<float>(const ClipRanges&, const PreparedMesh&, const std::vector<double>*, const PackedClip&, float*);
template void writeClipParentSections<double>(const ClipRanges&, const PreparedMesh&, const std::vector<double>*, const PackedClip&, double*);

void uploadClipWords(Backend& backend, BufferId words, const ClipRanges& r, const PreparedMesh& mesh,
                     const PackedClip& clip, bool withTable) {
  if (withTable) uploadPackedTable(backend, words);
  std::vector<uint32_t> own;
  resizeHuge(own, r.words - r.triangles, 0u);
  const uint64_t perParent = 4 * SFFD_MESH_TRIANGLE_STRIDE;
  std::copy_n(mesh.triangles.begin() + perParent * r.firstParent, perParent * r.parents, own.begin());
  std::copy(clip.headers.begin(), clip.headers.end(), own.begin() + (r.clipHeaders - r.triangles));
  backend.upload(words, r.triangles * 4, own.data(), own.size() * 4);
}

namespace {

template <class Real>
SubTriangleRecords clipRun(Backend& backend, const PreparedMesh& M, const PnOutput& pn, const ClipTriangles& clip,
                           double l, KernelVariant variant, size_t maxChunk) {
  const DeviceLimits& lim = backend.info().limits;
  const PackedTable& T = packedTable();
  PackedClip pc = packClip(clip);
  const size_t n = clip.triangles.size();
  const ClipRanges ranges = clipRanges(M, n, sizeof(Real));
  const std::vector<Real> reals = clipRealRange<Real>(ranges, M, &pn.records, pc);
  auto fits = [&](size_t bytes, const char* what) {
    if (bytes > lim.maxStorageBufferRange)
      throw Error(ErrorKind::Input, std::string("the job's ") + what + " (" + std::to_string(bytes >> 20) +
                                        " MiB) exceed one storage binding on this device (" +
                                        std::to_string(lim.maxStorageBufferRange >> 20) + " MiB); use a coarser mesh");
  };
  fits(reals.size() * sizeof(Real), "vertices, PN records and clip triangles");
  fits(ranges.words * 4, "triangles and clip triangles");
  auto make = [&](const void* data, size_t bytes) {
    BufferId b = backend.createBuffer(std::max<size_t>(bytes, 16));
    if (bytes && data) backend.upload(b, 0, data, bytes);
    return b;
  };
  BufferId bReals = make(reals.data(), reals.size() * sizeof(Real)), bWords = make(nullptr, ranges.words * 4);
  uploadClipWords(backend, bWords, ranges, M, pc, true);

  gpu::ClipParams params;
  params.table = {T.nmax, T.vertexWord, T.triangleWord, 0};
  params.target = {float(l), 0, 0, 0};
  auto dispatch = [&](const char* kernel, const char* label, size_t first, size_t count, std::vector<BufferBinding> extra) {
    params.range = {uint32_t(first), uint32_t(count), 0, 0};
    ranges.name(params);
    Dispatch d;
    d.kernel = kernel;
    d.label = label;
    d.variant = variant;
    d.params = &params;
    d.paramsSize = sizeof(params);
    d.buffers = {{SFFD_BINDING_CLIP_REALS, bReals}, {SFFD_BINDING_CLIP_WORDS, bWords}};
    d.buffers.insert(d.buffers.end(), extra.begin(), extra.end());
    gridFor(count, lim, d.groups);
    backend.dispatch(d);
    backend.barrier();
  };
  // Counting pass, exclusive scan on the host, then the writing pass in chunks whose output fits a binding.
  std::vector<uint32_t> counts(n);
  if (n) {
    dispatch("clip_count", "clip_count", 0, n, {});
    backend.download(bWords, ranges.counts * 4, counts.data(), n * 4);
  }
  std::vector<uint64_t> offsets(n + 1, 0);
  for (size_t i = 0; i < n; ++i) offsets[i + 1] = offsets[i] + counts[i];
  const uint64_t total = offsets[n];
  SubTriangleRecords R;
  R.headers.resize(4 * total);
  R.records.resize(total * SFFD_SUB_STRIDE * 4);
  const uint64_t recordBytes = SFFD_SUB_STRIDE * 4 * sizeof(Real);
  uint64_t maxSubs = lim.maxStorageBufferRange / recordBytes;
  if (maxChunk) maxSubs = std::min<uint64_t>(maxSubs, maxChunk);
  maxSubs = std::max<uint64_t>(maxSubs, 1);
  uint64_t largest = 0;
  for (uint32_t c : counts) largest = std::max<uint64_t>(largest, c);
  maxSubs = std::max(maxSubs, largest);
  BufferId bSubHdr = backend.createBuffer(std::max<uint64_t>(std::min(maxSubs, total) * 16, 16));
  BufferId bSubRec = backend.createBuffer(std::max<uint64_t>(std::min(maxSubs, total) * recordBytes, 16));
  // Each chunk writes from offset 0 of the sub-triangle buffers: its clip triangles' offsets are
  // stored relative to the chunk's first sub-triangle.
  std::vector<uint32_t> chunkOffsets(n);
  std::vector<Real> recs;
  for (size_t first = 0; first < n;) {
    size_t last = first;
    while (last < n && offsets[last + 1] - offsets[first] <= maxSubs) ++last;
    for (size_t i = first; i < last; ++i) chunkOffsets[i] = uint32_t(offsets[i] - offsets[first]);
    uint64_t subs = offsets[last] - offsets[first];
    backend.upload(bWords, (ranges.counts + first) * 4, chunkOffsets.data() + first, (last - first) * 4);
    dispatch("clip_write", "clip_write", first, last - first,
             {{SFFD_BINDING_SUB_HEADERS, bSubHdr}, {SFFD_BINDING_SUB_RECORDS, bSubRec}});
    if (subs) {
      backend.download(bSubHdr, 0, &R.headers[4 * offsets[first]], subs * 16);
      recs.resize(subs * SFFD_SUB_STRIDE * 4);
      backend.download(bSubRec, 0, recs.data(), subs * recordBytes);
      std::copy(recs.begin(), recs.end(), R.records.begin() + offsets[first] * SFFD_SUB_STRIDE * 4);
    }
    first = last;
  }
  backend.finish();
  for (BufferId b : {bReals, bWords, bSubHdr, bSubRec}) backend.destroyBuffer(b);
  R.timings = backend.takeTimings();
  return R;
}

}  // namespace

SubTriangleRecords regularClip(Backend& backend, const PreparedMesh& mesh, const PnOutput& pn,
                               const ClipTriangles& clip, double l, KernelVariant variant, size_t maxChunk) {
  if (variant.f64 && !backend.info().limits.float64)
    throw noFloat64Error(backend.info());
  auto t0 = std::chrono::steady_clock::now();
  SubTriangleRecords R = variant.f64 ? clipRun<double>(backend, mesh, pn, clip, l, variant, maxChunk)
                                     : clipRun<float>(backend, mesh, pn, clip, l, variant, maxChunk);
  R.wallMs = msSince(t0);
  return R;
}

}  // namespace sffd

namespace sffd {
namespace {

// Whether a parent site lies on parent edge e (corners e and e+1 do, edge sites of e do).
bool siteOnEdge(SubVertexKind kind, int e) {
  int k = int(kind);
  if (k < 3) return k == e || k == (e + 1) % 3;
  return k == 3 + e;
}

// The parents' data in Real only for parents [firstParent, + parents): a streamed chunk converts its own.
template <class Real>
SubTriangleRecords recordsCpu(const PreparedMesh& M, std::span<const double> pnRecords, size_t firstParent, size_t parents,
                              const std::vector<SubTriangle>& subs) {
  std::vector<Real> slots(size_t(SFFD_SLOT_NORMAL_STRIDE) * 4 * parents), rec(pnRecords.size());
  std::copy(pnRecords.begin(), pnRecords.end(), rec.begin());
  M.slotNormals(firstParent, parents, slots.data());
  SubTriangleRecords R;
  R.headers.assign(4 * subs.size(), 0);
  R.records.assign(subs.size() * SFFD_SUB_STRIDE * 4, 0.0);
  // Converted as convertReals does, one vertex at a time.
  auto v3 = [](const std::vector<double>& a, size_t i) { return RVec3<Real>{Real(a[4 * i]), Real(a[4 * i + 1]), Real(a[4 * i + 2])}; };
  const std::vector<double>&pos = M.positions, &nrm = M.normals;
  for (size_t s = 0; s < subs.size(); ++s) {
    const SubTriangle& st = subs[s];
    ParentT<Real> par;
    par.id = st.parent;
    for (int c = 0; c < 3; ++c) {
      par.verts[c] = M.triangles[8 * st.parent + c];
      par.welds[c] = M.triangles[8 * st.parent + 4 + c];
      par.V[c] = v3(pos, par.verts[c]);
      par.N[c] = v3(nrm, par.verts[c]);
    }
    if (st.parent < firstParent || st.parent - firstParent >= parents)
      throw std::logic_error("recordsFromSubTriangles: a sub-triangle's parent outside the given parents");
    par.pn = &rec[size_t(st.parent - firstParent) * SFFD_PN_STRIDE * 4];
    par.slot = &slots[size_t(st.parent - firstParent) * SFFD_SLOT_NORMAL_STRIDE * 4];
    SiteT<Real> site[3];
    SiteValueT<Real> val[3];
    for (int c = 0; c < 3; ++c) {
      site[c].kind = uint32_t(st.corners[c].kind);
      site[c].t = Real(st.corners[c].t);
      site[c].lam = RVec3<Real>::from(st.corners[c].lam);
      val[c] = par.evaluate(site[c]);
    }
    auto parentEdgeOf = [&](int c, int d) {
      for (int e = 0; e < 3; ++e)
        if (siteOnEdge(st.corners[c].kind, e) && siteOnEdge(st.corners[d].kind, e)) return e;
      return -1;
    };
    storeSubTriangle(par, site, val, parentEdgeOf, &R.records[s * SFFD_SUB_STRIDE * 4], &R.headers[4 * s]);
  }
  return R;
}

}  // namespace

SubTriangleRecords recordsFromSubTriangles(const PreparedMesh& mesh, const PnOutput& pn,
                                           const std::vector<SubTriangle>& subs, KernelVariant variant) {
  return recordsFromSubTriangles(mesh, pn.records, 0, mesh.triangleCount(), subs, variant);
}

SubTriangleRecords recordsFromSubTriangles(const PreparedMesh& mesh, std::span<const double> pnRecords, size_t firstParent,
                                           size_t parents, const std::vector<SubTriangle>& subs, KernelVariant variant) {
  auto t0 = std::chrono::steady_clock::now();
  SubTriangleRecords R = variant.f64 ? recordsCpu<double>(mesh, pnRecords, firstParent, parents, subs)
                                     : recordsCpu<float>(mesh, pnRecords, firstParent, parents, subs);
  R.wallMs = msSince(t0);
  R.timings.push_back({"clip", R.wallMs});
  return R;
}

}  // namespace sffd
