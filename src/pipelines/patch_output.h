// The result of the deform stage, for every method that makes patches (smooth, accurate): the
// tessellation vertices of each patch with their pre-images, and the welded output mesh.
// Plain data; the error analysis (error_metrics.h) and the writers read it.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "core/huge_pages.h"
#include "model/mesh.h"

namespace sffd {

// Tessellation at level L: per patch (L+1)(L+2)/2 vertices, row r = 0..L (i = L - r), position
// t = 0..r (k = t, j = r - t), index r(r+1)/2 + t, barycentrics (i, j, k) / L in the patch's
// sub-triangle; L^2 triangles, "up" (r,t),(r+1,t),(r+1,t+1) for t <= r and "down"
// (r,t),(r+1,t+1),(r,t+1) for t < r (METHOD.md 3.4 step 6).
int tessVertexCount(int level);
int tessTriangleCount(int level);
// The barycentrics (i, j, k) / L of the level's vertices in their sub-triangle, 3 a vertex in index order:
// the weights of the sub-triangle's corners in a vertex's pre-image (the producers compute them once a call).
std::vector<double> tessWeights(int level);
// The pre-images of one patch's vertices, 3 reals a vertex into `out`: vertex v at weights tessWeights()[3v..] of
// its sub-triangle's corners, which lie at barycentrics c0, c1, c2 of the parent (the weld keys on these bits).
void writeTessPreImages(const std::vector<double>& weights, const double* c0, const double* c1, const double* c2, double* out);
// The L^2 triangles of one patch as local vertex indices, 3 each.
std::vector<uint32_t> tessTriangles(int level);

struct PatchVertices {
  int level = 10;
  std::vector<uint32_t> parent;      // per patch: the original triangle
  std::vector<double> lamParent;     // per patch vertex: 3 barycentrics in the parent (the pre-image)
  std::vector<double> position;      // per patch vertex: 3 coordinates of the result
  std::vector<double> normal;        // per patch vertex: 3 coordinates of the unit shading normal
  // What the output carries from the input (carryAttributes; empty when the input has none).
  std::vector<double> texcoord;      // per patch vertex: 2, interpolated in the parent at lamParent
  std::vector<double> color;         // per patch vertex: 4 (RGBA), likewise
  std::vector<uint32_t> material, group;   // per patch: the parent's Mesh::triangleMaterial, triangleGroup
  std::vector<uint32_t> parentWeld;  // per patch: the input weldId of the parent's 3 corners (what the weld keys on)
  std::vector<Material> materials;   // the input's tables, as Mesh has them
  std::vector<std::string> groups, materialLibraries;
  size_t patchCount() const { return parent.size(); }
  // Room for `patches` patches of `level` in parent, lamParent, position and normal, reserved (address
  // space: a producer's resize() touches the pages as it fills them).
  void reserve(size_t patches) {
    const size_t reals = 3 * patches * size_t(tessVertexCount(level));
    parent.reserve(patches);
    reserveHuge(lamParent, reals);
    reserveHuge(position, reals);
    reserveHuge(normal, reals);
  }
  size_t vertexCount() const { return position.size() / 3; }
  // parent, lamParent, position and normal sized for `patches` patches, for a producer that writes every
  // element in place: a slice reused at the same size is not zero-filled again (the weld's slices are).
  void resize(size_t patches) {
    const size_t reals = 3 * patches * size_t(tessVertexCount(level));
    parent.resize(patches);
    for (auto* v : {&lamParent, &position, &normal}) v->resize(reals);
  }
};

// Fills the carried fields and parentWeld of `patches` from `input` (the mesh its parents index): texture coordinates
// and colours interpolated from the parent triangle's corners at each vertex's barycentric position,
// computed on the host in double, so equal on every backend for equal pre-images. A vertex on an
// edge or corner of its parent is interpolated from that edge's or corner's values alone, in an order
// fixed by weldId, so that neighbouring patches give it the same bits.
void carryAttributes(PatchVertices& patches, const Mesh& input);
// The same without the tables (materials, groups, materialLibraries): for a slice that a PatchWelder takes.
void carryPatchAttributes(PatchVertices& patches, const Mesh& input);

// Welds the patch vertices by where they lie on the input surface (parentWeld and the pre-images),
// not by their bits: a corner of the input is one location, a point on an input edge one location
// for every triangle on that edge (also a non-manifold fin, whose sheets bend the edge each its own
// way), a point inside a parent one location for its sub-triangles. Each location has one position,
// that of the patch of the lowest parent there, so the output is closed where the input is, and one
// vertex per distinct normal (apart by more than rounding, 1e-6), texture coordinate and colour bits
// (creases and seams split vertices,
// never positions); its vertices share a weldId, the location's index (Mesh::weldIdIsLocation, so the
// writers keep locations that round to one position apart). A triangle with two corners at
// one location (of a degenerate patch) is dropped, and so are the patches of a parent with two corners
// at one location (no area). The carried fields become the Mesh's.
Mesh weldPatchVertices(const PatchVertices& patches);

// weldPatchVertices a slice of patches at a time, for a producer that need not hold all the patch
// vertices at once (the smooth and accurate results weld each downloaded chunk in small slices, whose
// vertices stay in the cache): the slices, added in order, give the Mesh that weldPatchVertices gives for
// all of them together, tables left empty (the caller copies them).
//
// Streamed (a sink given): each add() hands the vertices and triangles it made to the sink as one piece
// (MeshSink::add; begin() and end() are the caller's), keeping only what later slices weld against (per
// vertex its normal and carried values, per location its position), not the Mesh; finish() is not called.
// The pieces, appended, are finish()'s Mesh. The parents must not decrease from patch to patch (as the
// smooth and accurate runs make them): a location's position is then final when it is made.
class PatchWelder {
 public:
  // `patches`: how many all the slices hold (the outputs are reserved for them).
  PatchWelder(int level, size_t patches, MeshSink* sink = nullptr);
  ~PatchWelder();
  void add(const PatchVertices& slice);   // carried fields and parentWeld filled (carryPatchAttributes)
  // Streamed, before the first add(): the slices' parents are triangles of `input` (in non-decreasing
  // order), so a location no later parent has (a patch's inner point, a parent's inner point once the next
  // parent comes, an input edge or corner after the last triangle on it) is forgotten with its vertices,
  // now and then: what the weld holds is the front of the parents still to come, not the output so far.
  // `compactAt`: the locations held before the first compaction (smaller only to test it); later ones
  // come at twice the locations kept by the last, and never below it. Few enough that the hash table of
  // what is held stays in the cache (2^16: teapot weld 32 ms, 1 M triangles at level 3 3.7 s; 2^14: 27 ms, 3.5 s).
  static constexpr size_t kCompactAt = size_t(1) << 14;
  void forgetPassedLocations(const Mesh& input, size_t compactAt = kCompactAt);
  size_t locationsHeld() const;   // those the weld holds now
  Mesh finish();
  // finish() with the tables of `input` (materials, groups, material libraries), as a result carries them.
  Mesh finish(const Mesh& input);
  // The Mesh of no vertices with the tables of `input` and the flags of a welded result (MeshSink::begin).
  static Mesh tablesOf(const Mesh& input);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The tessellation with every patch vertex its own vertex (so each can carry its own value, e.g. an
// error for colouring).
Mesh unweldedPatchMesh(const PatchVertices& patches);

}  // namespace sffd
