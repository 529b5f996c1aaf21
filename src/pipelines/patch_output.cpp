#include "pipelines/patch_output.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <sffd/error.h>

#include "core/huge_pages.h"
#include "core/job_budget.h"
#include "core/key3_map.h"
#include "model/mesh_topology.h"

namespace sffd {

namespace {
// Public (<sffd/deformer.h>): past DeformOptions::tess's range the counts are no level's, and overflow int.
int checkedLevel(int level, const char* call) {
  if (level < 1 || level > kMaxTessLevel)
    throw Error(ErrorKind::Input, std::string(call) + ": the tessellation level must be 1.." + std::to_string(kMaxTessLevel) +
                                      ", not " + std::to_string(level));
  return level;
}
}  // namespace

int tessVertexCount(int level) {
  checkedLevel(level, "tessVertexCount");
  return (level + 1) * (level + 2) / 2;
}
int tessTriangleCount(int level) { return checkedLevel(level, "tessTriangleCount") * level; }

std::vector<uint32_t> tessTriangles(int L) {
  std::vector<uint32_t> t;
  auto idx = [](int r, int c) { return uint32_t(r * (r + 1) / 2 + c); };
  for (int r = 0; r < L; ++r)
    for (int c = 0; c <= r; ++c) {
      t.insert(t.end(), {idx(r, c), idx(r + 1, c), idx(r + 1, c + 1)});
      if (c < r) t.insert(t.end(), {idx(r, c), idx(r + 1, c + 1), idx(r, c + 1)});
    }
  return t;
}

namespace {
// `values` (N doubles per vertex) at barycentric `lam` in triangle `t`: corners in weldId order, zero
// weights skipped (carryAttributes).
template <int N>
void interpolate(const std::vector<glm::vec<N, double>>& values, const std::array<uint32_t, 3>& t, const uint32_t* weld,
                 const double* lam, double* out) {
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int a, int b) { return weld[t[a]] < weld[t[b]]; });
  glm::vec<N, double> r(0.0);
  const glm::vec<N, double>* first = nullptr;
  bool shared[N];
  for (int c : order)
    if (lam[c] != 0.0) {
      const glm::vec<N, double>& v = values[t[c]];
      r += lam[c] * v;
      if (!first) first = &v;
      for (int i = 0; i < N; ++i) shared[i] = (first == &v || shared[i]) && v[i] == (*first)[i];
    }
  // A value that the corners share is kept exactly: the weights' sum may round off 1 (an opaque alpha came
  // out 0.9999999999999999, and the PLY writer then wrote an alpha channel of 255s).
  for (int i = 0; i < N; ++i) out[i] = first && shared[i] ? (*first)[i] : r[i];
}
}  // namespace

void carryPatchAttributes(PatchVertices& P, const Mesh& input) {
  const size_t nv = size_t(tessVertexCount(P.level));
  const bool uv = !input.texcoords.empty(), rgba = !input.colors.empty();
  P.texcoord.assign(uv ? 2 * P.vertexCount() : 0, 0.0);
  P.color.assign(rgba ? 4 * P.vertexCount() : 0, 0.0);
  for (size_t g = 0; (uv || rgba) && g < P.vertexCount(); ++g) {
    const auto& t = input.triangles[P.parent[g / nv]];
    if (uv) interpolate(input.texcoords, t, input.weldId.data(), &P.lamParent[3 * g], &P.texcoord[2 * g]);
    if (rgba) interpolate(input.colors, t, input.weldId.data(), &P.lamParent[3 * g], &P.color[4 * g]);
  }
  auto perPatch = [&](const std::vector<uint32_t>& perTriangle, std::vector<uint32_t>& out) {
    out.clear();
    if (!perTriangle.empty())
      for (uint32_t parent : P.parent) out.push_back(perTriangle[parent]);
  };
  P.parentWeld.resize(3 * P.patchCount());
  for (size_t p = 0; p < P.patchCount(); ++p)
    for (int c = 0; c < 3; ++c) P.parentWeld[3 * p + c] = input.weldId[input.triangles[P.parent[p]][c]];
  perPatch(input.triangleMaterial, P.material);
  perPatch(input.triangleGroup, P.group);
}

void carryAttributes(PatchVertices& P, const Mesh& input) {
  carryPatchAttributes(P, input);
  P.materials = input.materials;
  P.groups = input.groups;
  P.materialLibraries = input.materialLibraries;
}

namespace {
uint64_t bitsOf(double x) {
  uint64_t b;
  std::memcpy(&b, &x, 8);
  return b;
}

// Whether N doubles have the same bits (as memcmp, without its call: the weld asks it for most vertices).
template <int N>
bool sameBits(const double* a, const double* b) {
  bool same = true;
  for (int i = 0; i < N; ++i) same &= bitsOf(a[i]) == bitsOf(b[i]);
  return same;
}

// Whether two unit normals at one location are one vertex's: the same bits, or apart by rounding alone.
// The kernels give a shared point's normal the same bits from both patches where they run in a fixed
// order (strict, and the CPU and Mesa's drivers in fast mode too); a GPU that fuses multiply-adds can
// differ by an ulp or two from one patch to the next, which must not split a smooth surface's vertex.
// Creases, the splits that matter, part normals by degrees.
bool sameNormal(const double* a, const double* b) {
  if (sameBits<3>(a, b)) return true;
  constexpr double kRounding = 1e-6;
  return std::abs(a[0] - b[0]) <= kRounding && std::abs(a[1] - b[1]) <= kRounding && std::abs(a[2] - b[2]) <= kRounding;
}

// Where on the input surface a patch-boundary vertex lies, from its pre-image: a corner by the input's
// weldId, a parent edge by its two welded corners and the barycentric of the higher one (the clip
// measures edge points from the lower weldId and the tessellation sums the same two products on
// both sides, so the bits agree), a point inside the parent by the parent and its barycentrics.
class Locations {
 public:
  // Keys expected: a patch's 3 (level - 1) edge points, each shared by two patches, and about one corner a
  // patch off the input's corners (where a parent is split). The table holds twice as many slots (32 B each,
  // all touched: at 1 M patches of level 3, 8 M slots), and grows if a mesh has more.
  explicit Locations(size_t patches, int level) : other_(patches * (3 * size_t(level) - 1) / 2) {}
  static constexpr uint32_t kNone = ~0u;

  // The slot that holds the location of the vertex at pre-image `lam` of a patch of `parent`, whose
  // corners have weldIds `w` (kNone when it has none yet); with lastUse() given, `until` becomes the last
  // parent that can reach that location (parents of later patches do not decrease).
  uint32_t& of(uint32_t parent, const uint32_t* w, const double* lam, uint32_t& until) {
    const int zeros = (lam[0] == 0) + (lam[1] == 0) + (lam[2] == 0);
    if (zeros == 2) return corner(w[lam[0] != 0 ? 0 : lam[1] != 0 ? 1 : 2], until);
    if (zeros == 1) {
      const int z = lam[0] == 0 ? 0 : lam[1] == 0 ? 1 : 2, a = (z + 1) % 3, b = (z + 2) % 3;
      if (w[a] == w[b]) return corner(w[a], until);   // an edge of no length: all of it is that corner
      const int hi = w[a] < w[b] ? b : a;
      // Every parent on that edge has both corners.
      if (!lastUse_.empty()) until = std::min(lastUse_[w[a]], lastUse_[w[b]]);
      return other_.of({uint64_t(std::min(w[a], w[b])) << 32 | std::max(w[a], w[b]), bitsOf(lam[hi]), 0}, kNone);
    }
    // Apart from the edge keys: their last word is 0, the bits of +0, and inside a parent no barycentric
    // is 0.
    until = parent;
    return other_.of({uint64_t(parent), bitsOf(lam[0]), bitsOf(lam[1])}, kNone);
  }
  // Per weldId of the input, the last triangle with a corner there.
  void setLastUse(std::vector<uint32_t> lastUse) { lastUse_ = std::move(lastUse); }
  // Gives each location v the slot to[v], or forgets it (kNone).
  void remap(const std::vector<uint32_t>& to) {
    for (uint32_t& c : corner_)
      if (c != kNone) c = to[c];
    other_.remap(to, kNone);
  }

 private:
  uint32_t& corner(uint32_t weldId, uint32_t& until) {
    if (weldId >= corner_.size()) corner_.resize(size_t(weldId) + 1, kNone);
    if (!lastUse_.empty()) until = lastUse_[weldId];
    return corner_[weldId];
  }
  std::vector<uint32_t> corner_;
  Key3Map other_;
  std::vector<uint32_t> lastUse_;
};

bool onPatchBoundary(int v, int L) {
  const int r = int((std::sqrt(8.0 * v + 1) - 1) / 2), c = v - r * (r + 1) / 2;
  return c == 0 || c == r || r == L;
}
}  // namespace

struct PatchWelder::Impl {
  int level;
  size_t patches;   // all that will come: the outputs are reserved for them
  std::vector<uint32_t> local;   // tessTriangles
  std::vector<char> boundary;    // per patch vertex
  Mesh m;   // per vertex slot its normal and carried values, weldId: its location's slot
  // Per location: its position (from the patch of the lowest parent that reaches it, so that every
  // triangle there uses the same bits where the sides disagree: a fin, a sliver) and first vertex;
  // per vertex: the next vertex of its location (one per distinct normal and carried value).
  struct Location {
    uint32_t parent, first;
    glm::dvec3 position;
  };
  std::vector<Location> locs;
  std::vector<uint32_t> next;
  Locations where;
  bool started = false;
  MeshSink* sink;       // streamed: the pieces go here
  Mesh piece;           // streamed: the vertices and triangles of the last add()
  size_t emitted = 0;   // streamed: the vertex slots handed over
  uint32_t lastParent = 0;
  // Forgetting (forgetPassedLocations): the slots are compacted, so a slot's location and vertex numbers (the
  // output's) are kept per slot; until: the last parent that can reach the location.
  bool forgetting = false;
  std::vector<uint32_t> locUntil, locId, vertexId;
  size_t locTotal = 0, vertexTotal = 0;   // made so far: the next location's and vertex's numbers
  size_t minCompact = 0, compactAt = 0;   // locations held when the next add() compacts: at least minCompact

  Impl(int level, size_t patches, MeshSink* sink)
      : level(level), patches(patches), local(tessTriangles(level)), where(patches, level), sink(sink) {
    const int nv = tessVertexCount(level);
    boundary.resize(nv);
    for (int v = 0; v < nv; ++v) boundary[v] = onPatchBoundary(v, level);
    m.normalsFromFile = true;
    m.weldIdIsLocation = true;
  }

  // Reserved for at most every patch vertex and triangle (address space only: no growth copies, and the
  // pages not reached are never touched), in huge pages (core/huge_pages.h).
  void reserve(const PatchVertices& P) {
    const size_t vertices = patches * size_t(tessVertexCount(level)), triangles = patches * local.size() / 3;
    reserveHuge(m.normals, vertices);
    if (!P.texcoord.empty()) reserveHuge(m.texcoords, vertices);
    if (!P.color.empty()) reserveHuge(m.colors, vertices);
    reserveHuge(m.weldId, vertices);
    reserveHuge(next, vertices);
    reserveHuge(locs, vertices);
    if (sink) return;   // the triangles go with each piece
    reserveHuge(m.triangles, triangles);
    if (!P.material.empty()) reserveHuge(m.triangleMaterial, triangles);
    if (!P.group.empty()) reserveHuge(m.triangleGroup, triangles);
  }

  void add(const PatchVertices& P) {
    if (P.parentWeld.size() != 3 * P.patchCount())
      throw std::logic_error("weldPatchVertices: parentWeld not filled (carryAttributes)");
    if (P.level != level) throw std::logic_error("PatchWelder: patches of another level");
    if (!started) reserve(P), started = true;
    if (forgetting && locs.size() >= compactAt && P.patchCount()) compact(P.parent[0]);
    const int nv = tessVertexCount(level);
    const bool uv = !P.texcoord.empty(), rgba = !P.color.empty();
    auto sameVertex = [&](uint32_t i, size_t g) {
      return sameNormal(&m.normals[i][0], &P.normal[3 * g]) && (!uv || sameBits<2>(&m.texcoords[i][0], &P.texcoord[2 * g])) &&
             (!rgba || sameBits<4>(&m.colors[i][0], &P.color[4 * g]));
    };
    auto newVertex = [&](size_t g, uint32_t loc) {
      const uint32_t i = uint32_t(m.normals.size());
      m.normals.push_back({P.normal[3 * g], P.normal[3 * g + 1], P.normal[3 * g + 2]});
      if (uv) m.texcoords.push_back({P.texcoord[2 * g], P.texcoord[2 * g + 1]});
      if (rgba) m.colors.push_back({P.color[4 * g], P.color[4 * g + 1], P.color[4 * g + 2], P.color[4 * g + 3]});
      m.weldId.push_back(loc);
      next.push_back(Locations::kNone);
      if (forgetting) vertexId.push_back(uint32_t(vertexTotal));
      ++vertexTotal;
      return i;
    };
    auto positionOf = [&](size_t g) { return glm::dvec3(P.position[3 * g], P.position[3 * g + 1], P.position[3 * g + 2]); };
    std::vector<uint32_t> map(nv);
    for (size_t p = 0; p < P.patchCount(); ++p) {
      const uint32_t parent = P.parent[p];
      if (sink && parent < lastParent) throw std::logic_error("PatchWelder: streamed patches out of parent order");
      lastParent = parent;
      // A parent with two corners at one location has no area, and neither has its part of the surface: its
      // patch, made from normals that need not agree at that location (a duplicate vertex of an unwelded file),
      // stuck out of the surface, and its edge points could give the real triangles' edge their positions.
      if (weldsCollapsed(P.parentWeld[3 * p], P.parentWeld[3 * p + 1], P.parentWeld[3 * p + 2])) continue;
      for (int v = 0; v < nv; ++v) {
        const size_t g = p * nv + v;
        uint32_t fresh = Locations::kNone, until = parent;
        // A patch's inner vertices are its own.
        uint32_t& loc = boundary[v] ? where.of(parent, &P.parentWeld[3 * p], &P.lamParent[3 * g], until) : fresh;
        if (loc == Locations::kNone) {
          loc = uint32_t(locs.size());
          locs.push_back({parent, uint32_t(m.normals.size()), positionOf(g)});
          if (forgetting) locUntil.push_back(until), locId.push_back(uint32_t(locTotal));
          ++locTotal;
          map[v] = newVertex(g, loc);
          continue;
        }
        Location& L = locs[loc];
        if (parent < L.parent) L.parent = parent, L.position = positionOf(g);
        uint32_t i = L.first;
        while (!sameVertex(i, g) && next[i] != Locations::kNone) i = next[i];
        if (!sameVertex(i, g)) i = next[i] = newVertex(g, loc);
        map[v] = i;
      }
      for (size_t i = 0; i < local.size(); i += 3) {
        std::array<uint32_t, 3> t{map[local[i]], map[local[i + 1]], map[local[i + 2]]};
        const uint32_t* w = m.weldId.data();
        if (weldsCollapsed(w[t[0]], w[t[1]], w[t[2]])) continue;   // a collapsed corner of a degenerate patch
        if (forgetting) t = {vertexId[t[0]], vertexId[t[1]], vertexId[t[2]]};
        m.triangles.push_back(t);
        if (!P.material.empty()) m.triangleMaterial.push_back(P.material[p]);
        if (!P.group.empty()) m.triangleGroup.push_back(P.group[p]);
      }
    }
    if (sink) emit();
  }

  // The vertices made since the last piece (each location's position final: parents do not decrease) and
  // the triangles, to the sink; the triangles are not kept.
  void emit() {
    const size_t n = m.normals.size();
    piece.positions.clear();
    for (size_t i = emitted; i < n; ++i) piece.positions.push_back(locs[m.weldId[i]].position);
    auto tail = [&](const auto& from, auto& to) { to.assign(from.begin() + std::ptrdiff_t(std::min(emitted, from.size())), from.end()); };
    tail(m.normals, piece.normals);
    tail(m.texcoords, piece.texcoords);
    tail(m.colors, piece.colors);
    tail(m.weldId, piece.weldId);
    if (forgetting)
      for (uint32_t& w : piece.weldId) w = locId[w];
    piece.triangles.swap(m.triangles);
    piece.triangleMaterial.swap(m.triangleMaterial);
    piece.triangleGroup.swap(m.triangleGroup);
    m.triangles.clear(), m.triangleMaterial.clear(), m.triangleGroup.clear();
    sink->add(piece, vertexTotal - (n - emitted));
    emitted = n;
  }

  // Drops the locations no patch of parent `now` or later can reach, with their vertices (all handed
  // over: compact() runs between pieces), and renumbers the slots of the rest in order.
  void compact(uint32_t now) {
    constexpr uint32_t kNone = Locations::kNone;
    std::vector<uint32_t> toLoc(locs.size(), kNone), toVertex(m.normals.size(), kNone);
    size_t kept = 0;
    for (size_t l = 0; l < locs.size(); ++l)
      if (locUntil[l] >= now) toLoc[l] = uint32_t(kept), locs[kept] = locs[l], locUntil[kept] = locUntil[l], locId[kept] = locId[l], ++kept;
    locs.resize(kept), locUntil.resize(kept), locId.resize(kept);
    const bool uv = !m.texcoords.empty(), rgba = !m.colors.empty();
    size_t keptV = 0;
    for (size_t i = 0; i < m.normals.size(); ++i) {
      if (toLoc[m.weldId[i]] == kNone) continue;
      toVertex[i] = uint32_t(keptV);
      m.normals[keptV] = m.normals[i];
      if (uv) m.texcoords[keptV] = m.texcoords[i];
      if (rgba) m.colors[keptV] = m.colors[i];
      m.weldId[keptV] = toLoc[m.weldId[i]];
      next[keptV] = next[i];
      vertexId[keptV] = vertexId[i];
      ++keptV;
    }
    for (auto* v : {&m.weldId, &next, &vertexId}) v->resize(keptV);
    m.normals.resize(keptV);
    if (uv) m.texcoords.resize(keptV);
    if (rgba) m.colors.resize(keptV);
    for (size_t i = 0; i < keptV; ++i)
      if (next[i] != kNone) next[i] = toVertex[next[i]];
    for (Location& L : locs) L.first = toVertex[L.first];
    where.remap(toLoc);
    emitted = keptV;
    compactAt = std::max(minCompact, 2 * kept);
  }

  Mesh finish() {
    if (forgetting) throw std::logic_error("PatchWelder: finish() after forgetPassedLocations");
    reserveHuge(m.positions, m.normals.size());
    for (size_t i = 0; i < m.normals.size(); ++i) m.positions.push_back(locs[m.weldId[i]].position);
    freeStorage(locs);
    freeStorage(next);
    return std::move(m);
  }

  void forgetPassed(const Mesh& input, size_t compactFrom) {
    if (!sink || started) throw std::logic_error("PatchWelder: forgetPassedLocations needs a sink, before the first add()");
    std::vector<uint32_t> lastUse;
    for (uint32_t t = 0; t < input.triangles.size(); ++t)
      for (uint32_t v : input.triangles[t]) {
        const uint32_t w = input.weldId[v];
        if (w >= lastUse.size()) lastUse.resize(size_t(w) + 1, 0);
        lastUse[w] = t;
      }
    where = Locations(0, level);   // no table for every patch's keys: it holds the front's
    where.setLastUse(std::move(lastUse));
    forgetting = true;
    minCompact = compactAt = compactFrom;
    patches = 0;   // nothing reserved for all of them: the slots stay few
  }
};

PatchWelder::PatchWelder(int level, size_t patches, MeshSink* sink) : impl_(std::make_unique<Impl>(level, patches, sink)) {}
PatchWelder::~PatchWelder() = default;
void PatchWelder::add(const PatchVertices& patches) { impl_->add(patches); }
void PatchWelder::forgetPassedLocations(const Mesh& input, size_t compactAt) { impl_->forgetPassed(input, compactAt); }
size_t PatchWelder::locationsHeld() const { return impl_->locs.size(); }
Mesh PatchWelder::finish() { return impl_->finish(); }
Mesh PatchWelder::finish(const Mesh& input) {
  Mesh m = impl_->finish();
  m.materials = input.materials;
  m.groups = input.groups;
  m.materialLibraries = input.materialLibraries;
  return m;
}

Mesh PatchWelder::tablesOf(const Mesh& input) {
  Mesh m;
  m.normalsFromFile = true;
  m.weldIdIsLocation = true;
  m.materials = input.materials;
  m.groups = input.groups;
  m.materialLibraries = input.materialLibraries;
  return m;
}

Mesh weldPatchVertices(const PatchVertices& P) {
  PatchWelder weld(P.level, P.patchCount());
  weld.add(P);
  Mesh m = weld.finish();
  m.materials = P.materials;
  m.groups = P.groups;
  m.materialLibraries = P.materialLibraries;
  return m;
}

Mesh unweldedPatchMesh(const PatchVertices& pv) {
  Mesh m;
  const size_t nv = size_t(tessVertexCount(pv.level));
  std::vector<uint32_t> local = tessTriangles(pv.level);
  m.positions.reserve(pv.vertexCount());
  m.normals.reserve(pv.vertexCount());
  for (size_t v = 0; v < pv.vertexCount(); ++v) {
    m.positions.push_back({pv.position[3 * v], pv.position[3 * v + 1], pv.position[3 * v + 2]});
    m.normals.push_back({pv.normal[3 * v], pv.normal[3 * v + 1], pv.normal[3 * v + 2]});
    m.weldId.push_back(uint32_t(v));
  }
  for (size_t p = 0; p < pv.patchCount(); ++p)
    for (size_t i = 0; i < local.size(); i += 3)
      m.triangles.push_back({uint32_t(p * nv + local[i]), uint32_t(p * nv + local[i + 1]), uint32_t(p * nv + local[i + 2])});
  return m;
}

}  // namespace sffd
