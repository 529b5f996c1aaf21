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

std::vector<double> tessWeights(int L) {
  std::vector<double> w;
  for (int r = 0; r <= L; ++r)
    for (int c = 0; c <= r; ++c) w.insert(w.end(), {double(L - r) / L, double(r - c) / L, double(c) / L});
  return w;
}

void writeTessPreImages(const std::vector<double>& w, const double* c0, const double* c1, const double* c2, double* out) {
  for (size_t v = 0; v < w.size(); v += 3, out += 3)
    for (int a = 0; a < 3; ++a) out[a] = (w[v] * c0[a] + w[v + 1] * c1[a]) + w[v + 2] * c2[a];
}

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
  // `keys`: about how many the table will hold (it holds twice as many slots, 32 B each, all touched, and
  // grows if a mesh has more).
  explicit Locations(size_t keys) : other_(keys) {}
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
  // Gives each location v the slot to[v], or forgets it (kNone); `room`: the keys expected before the next remap.
  void remap(const std::vector<uint32_t>& to, size_t room) {
    for (uint32_t& c : corner_)
      if (c != kNone) c = to[c];
    other_.remap(to, kNone, room);
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
  static constexpr uint32_t kNone = Locations::kNone;
  int level;
  size_t patches;   // all that will come: the outputs are reserved for them
  std::vector<uint32_t> local;   // tessTriangles
  std::vector<char> boundary;    // per patch vertex
  // The output, each vertex's weldId its location's number: streamed, the piece of the last add() (its storage
  // reused), else the whole Mesh. A patch's inner vertices go only here: no other patch reaches them.
  Mesh out;
  // Per location on a patch's boundary: its position (from the patch of the lowest parent that reaches it, so
  // that every triangle there uses the same bits where the sides disagree: a fin, a sliver), first slot, until
  // (the last parent that can reach it, forgetPassedLocations) and number.
  struct Location {
    uint32_t parent, first;
    glm::dvec3 position;
  };
  std::vector<Location> locs;
  std::vector<uint32_t> locUntil, locId;
  // Per slot (a vertex of a boundary location: one per distinct normal and carried value) those values, for
  // the next patches' vertices there to match, its location's slot, the location's next slot and its vertex
  // number. Compaction renumbers the slots, never the numbers.
  std::vector<glm::dvec3> normals;
  std::vector<glm::dvec2> texcoords;
  std::vector<glm::dvec4> colors;
  std::vector<uint32_t> slotLoc, next, vertexId;
  Locations where;
  std::vector<uint32_t> vertexOf, locationOf;   // per vertex of the current patch: its vertex and location numbers
  size_t made = 0;   // the output's vertices: in add(), its arrays are longer (the room for a patch's)
  bool uv = false, rgba = false;   // the slice has texture coordinates, colours
  bool started = false;
  MeshSink* sink;   // streamed: the pieces go here
  uint32_t lastParent = 0;
  bool forgetting = false;   // forgetPassedLocations
  size_t locTotal = 0, vertexTotal = 0;   // made so far: the next location's and vertex's numbers
  size_t minCompact = 0, compactAt = 0;   // locations held when the next add() compacts: at least minCompact

  // The keys of all the patches: a patch's 3 (level - 1) edge points, each shared by two patches, and about
  // one corner a patch off the input's corners (where a parent is split): at 1 M patches of level 3, 8 M slots.
  static size_t keysOf(size_t patches, int level) { return patches * (3 * size_t(level) - 1) / 2; }

  Impl(int level, size_t patches, MeshSink* sink)
      : level(level), patches(patches), local(tessTriangles(level)), where(keysOf(patches, level)), sink(sink) {
    const int nv = tessVertexCount(level);
    boundary.resize(nv);
    for (int v = 0; v < nv; ++v) boundary[v] = onPatchBoundary(v, level);
    vertexOf.resize(nv), locationOf.resize(nv);
  }

  // Reserved for at most every patch vertex and triangle (address space only: no growth copies, and the
  // pages not reached are never touched), in huge pages (core/huge_pages.h).
  void reserve(const PatchVertices& P) {
    const size_t vertices = patches * size_t(tessVertexCount(level)), triangles = patches * local.size() / 3;
    reserveHuge(normals, vertices);
    if (!P.texcoord.empty()) reserveHuge(texcoords, vertices);
    if (!P.color.empty()) reserveHuge(colors, vertices);
    for (auto* v : {&slotLoc, &next, &vertexId, &locUntil, &locId}) reserveHuge(*v, vertices);
    reserveHuge(locs, vertices);
    if (sink) return;   // the output goes a piece at a time
    reserveHuge(out.positions, vertices);
    reserveHuge(out.normals, vertices);
    if (!P.texcoord.empty()) reserveHuge(out.texcoords, vertices);
    if (!P.color.empty()) reserveHuge(out.colors, vertices);
    reserveHuge(out.weldId, vertices);
    reserveHuge(out.triangles, triangles);
    if (!P.material.empty()) reserveHuge(out.triangleMaterial, triangles);
    if (!P.group.empty()) reserveHuge(out.triangleGroup, triangles);
  }

  void add(const PatchVertices& P) {
    if (P.parentWeld.size() != 3 * P.patchCount())
      throw std::logic_error("weldPatchVertices: parentWeld not filled (carryAttributes)");
    if (P.level != level) throw std::logic_error("PatchWelder: patches of another level");
    if (!started) reserve(P), started = true;
    if (forgetting && locs.size() >= compactAt && P.patchCount()) compact(P.parent[0]);
    const size_t nv = vertexOf.size(), nt = local.size() / 3;
    uv = !P.texcoord.empty(), rgba = !P.color.empty();
    const bool material = !P.material.empty(), group = !P.group.empty();
    for (size_t p = 0; p < P.patchCount(); ++p) {
      const uint32_t parent = P.parent[p];
      if (sink && parent < lastParent) throw std::logic_error("PatchWelder: streamed patches out of parent order");
      lastParent = parent;
      // A parent with two corners at one location has no area, and neither has its part of the surface: its
      // patch, made from normals that need not agree at that location (a duplicate vertex of an unwelded file),
      // stuck out of the surface, and its edge points could give the real triangles' edge their positions.
      if (weldsCollapsed(P.parentWeld[3 * p], P.parentWeld[3 * p + 1], P.parentWeld[3 * p + 2])) continue;
      // Room for a new vertex per patch vertex and every triangle, written in place and cut to what was made:
      // no push_back's checks per element.
      made = out.positions.size();
      for (auto* v : {&out.positions, &out.normals}) v->resize(made + nv);
      if (uv) out.texcoords.resize(made + nv);
      if (rgba) out.colors.resize(made + nv);
      out.weldId.resize(made + nv);
      for (size_t v = 0; v < nv; ++v) {
        const size_t g = p * nv + v;
        if (boundary[v]) boundaryVertex(P, p, v);
        else locationOf[v] = uint32_t(locTotal++), vertexOf[v] = newVertex(P, g, &P.position[3 * g], locationOf[v]);
      }
      for (auto* v : {&out.positions, &out.normals}) v->resize(made);
      if (uv) out.texcoords.resize(made);
      if (rgba) out.colors.resize(made);
      out.weldId.resize(made);
      size_t t = out.triangles.size();
      out.triangles.resize(t + nt);
      for (size_t i = 0; i < local.size(); i += 3) {
        const uint32_t a = local[i], b = local[i + 1], c = local[i + 2];
        if (weldsCollapsed(locationOf[a], locationOf[b], locationOf[c])) continue;   // a collapsed corner of a degenerate patch
        out.triangles[t++] = {vertexOf[a], vertexOf[b], vertexOf[c]};
      }
      out.triangles.resize(t);
      if (material) out.triangleMaterial.resize(t, P.material[p]);
      if (group) out.triangleGroup.resize(t, P.group[p]);
    }
    if (sink) emit();
  }

  // Vertex v of patch p, on the patch's boundary: its location (found or made) and the vertex there with its
  // normal and carried values (found or made).
  void boundaryVertex(const PatchVertices& P, size_t p, size_t v) {
    const uint32_t parent = P.parent[p];
    const size_t g = p * vertexOf.size() + v;
    uint32_t until = parent;
    uint32_t& loc = where.of(parent, &P.parentWeld[3 * p], &P.lamParent[3 * g], until);
    uint32_t i;
    if (loc == kNone) {
      loc = uint32_t(locs.size());
      locs.push_back({parent, uint32_t(slotLoc.size()), {P.position[3 * g], P.position[3 * g + 1], P.position[3 * g + 2]}});
      locUntil.push_back(until), locId.push_back(uint32_t(locTotal++));
      i = newSlot(P, g, loc);
    } else {
      Location& L = locs[loc];
      if (parent < L.parent) {   // not streamed: the vertices made there so far move with it
        L.parent = parent, L.position = {P.position[3 * g], P.position[3 * g + 1], P.position[3 * g + 2]};
        for (uint32_t j = L.first; j != kNone; j = next[j]) out.positions[vertexId[j]] = L.position;
      }
      i = L.first;
      while (!sameVertex(P, i, g) && next[i] != kNone) i = next[i];
      if (!sameVertex(P, i, g)) i = next[i] = newSlot(P, g, loc);
    }
    vertexOf[v] = vertexId[i], locationOf[v] = locId[loc];
  }

  bool sameVertex(const PatchVertices& P, uint32_t i, size_t g) const {
    return sameNormal(&normals[i][0], &P.normal[3 * g]) && (!uv || sameBits<2>(&texcoords[i][0], &P.texcoord[2 * g])) &&
           (!rgba || sameBits<4>(&colors[i][0], &P.color[4 * g]));
  }

  // A slot for patch vertex g at location slot `loc`, and its vertex.
  uint32_t newSlot(const PatchVertices& P, size_t g, uint32_t loc) {
    normals.push_back({P.normal[3 * g], P.normal[3 * g + 1], P.normal[3 * g + 2]});
    if (uv) texcoords.push_back({P.texcoord[2 * g], P.texcoord[2 * g + 1]});
    if (rgba) colors.push_back({P.color[4 * g], P.color[4 * g + 1], P.color[4 * g + 2], P.color[4 * g + 3]});
    slotLoc.push_back(loc);
    next.push_back(kNone);
    vertexId.push_back(newVertex(P, g, &locs[loc].position[0], locId[loc]));
    return uint32_t(slotLoc.size() - 1);
  }

  // An output vertex at `position` with patch vertex g's normal and carried values, at location number
  // `location`, into the room add() made: its number.
  uint32_t newVertex(const PatchVertices& P, size_t g, const double* position, uint32_t location) {
    out.positions[made] = {position[0], position[1], position[2]};
    out.normals[made] = {P.normal[3 * g], P.normal[3 * g + 1], P.normal[3 * g + 2]};
    if (uv) out.texcoords[made] = {P.texcoord[2 * g], P.texcoord[2 * g + 1]};
    if (rgba) out.colors[made] = {P.color[4 * g], P.color[4 * g + 1], P.color[4 * g + 2], P.color[4 * g + 3]};
    out.weldId[made++] = location;
    return uint32_t(vertexTotal++);
  }

  // The vertices and triangles made since the last piece to the sink (each position final: parents do not
  // decrease), and none of them kept.
  void emit() {
    sink->add(out, vertexTotal - out.positions.size());
    for (auto* v : {&out.positions, &out.normals}) v->clear();
    out.texcoords.clear(), out.colors.clear(), out.weldId.clear();
    out.triangles.clear(), out.triangleMaterial.clear(), out.triangleGroup.clear();
  }

  // Drops the locations no patch of parent `now` or later can reach, with their slots (their vertices all
  // handed over), and renumbers the slots of the rest in order.
  void compact(uint32_t now) {
    std::vector<uint32_t> toLoc(locs.size(), kNone), toSlot(slotLoc.size(), kNone);
    size_t kept = 0;
    for (size_t l = 0; l < locs.size(); ++l)
      if (locUntil[l] >= now) toLoc[l] = uint32_t(kept), locs[kept] = locs[l], locUntil[kept] = locUntil[l], locId[kept] = locId[l], ++kept;
    locs.resize(kept), locUntil.resize(kept), locId.resize(kept);
    const bool uv = !texcoords.empty(), rgba = !colors.empty();
    size_t keptS = 0;
    for (size_t i = 0; i < slotLoc.size(); ++i) {
      if (toLoc[slotLoc[i]] == kNone) continue;
      toSlot[i] = uint32_t(keptS);
      normals[keptS] = normals[i];
      if (uv) texcoords[keptS] = texcoords[i];
      if (rgba) colors[keptS] = colors[i];
      slotLoc[keptS] = toLoc[slotLoc[i]];
      next[keptS] = next[i];
      vertexId[keptS] = vertexId[i];
      ++keptS;
    }
    for (auto* v : {&slotLoc, &next, &vertexId}) v->resize(keptS);
    normals.resize(keptS);
    if (uv) texcoords.resize(keptS);
    if (rgba) colors.resize(keptS);
    for (uint32_t& n : next)
      if (n != kNone) n = toSlot[n];
    for (Location& L : locs) L.first = toSlot[L.first];
    compactAt = std::max(minCompact, 2 * kept);
    where.remap(toLoc, compactAt);   // a key a location at most, and the next compaction comes at compactAt
  }

  Mesh finish() {
    if (forgetting) throw std::logic_error("PatchWelder: finish() after forgetPassedLocations");
    if (sink) throw std::logic_error("PatchWelder: finish() of a streamed weld (its pieces went to the sink)");
    out.normalsFromFile = true;
    out.weldIdIsLocation = true;
    freeStorage(locs);
    freeStorage(next);
    freeStorage(normals);
    return std::move(out);
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
    where = Locations(compactFrom);   // no table for every patch's keys: it holds the front's (a key a location)
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
