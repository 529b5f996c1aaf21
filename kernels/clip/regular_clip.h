// Kernel K2 "clip" with the improved regular clipping of Lu & Feng (METHOD.md 3.3, 4.2): every
// triangle split by the pattern of its edges' segment counts ceil(len / l), into near-regular
// sub-triangles lifted onto the PN surface, crack-free by construction. Also turns knot-box clipping
// (knot_box_clip.h) into the same sub-triangle records, so both clippings feed one deform stage.
#pragma once
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "core/backend.h"
#include "kernels/clip/split_pattern_table.h"
#include "kernels/common/shader_layout.h"
#include "kernels/pn/pn_triangles.h"
#include "model/prepared_mesh.h"
#include "model/sub_triangles.h"

namespace sffd {

// A piece of a parent triangle that one split pattern covers. Without pre-split it is the parent
// itself; triangles whose edges need more than Nmax segments are first bisected (longest edge first,
// conforming across shared edges) into clip triangles that need at most Nmax.
struct ClipTriangle {
  uint32_t parent = 0;
  std::array<uint32_t, 3> weld{};      // corner weld ids (split points get fresh ids above the mesh's)
  std::array<SubVertex, 3> corners;    // where each corner lies on the parent
  std::array<glm::dvec3, 3> flat{};    // corner positions on the flat parent
  // Per clip edge e (corner e -> e+1): the parent edge it lies on (-1: inside the parent) and the
  // parameters of its two corners along that parent edge, from its lower-weld endpoint.
  std::array<int, 3> parentEdge{-1, -1, -1};
  std::array<std::array<double, 2>, 3> edgeParam{};
};

struct ClipTriangles {
  std::vector<ClipTriangle> triangles;
  size_t presplitParents = 0;   // parents that needed the pre-split
};

// Whether the clip kernels can take target edge length l, which they read as a float (ClipParams.target):
// it must be a normal float, since GPUs flush smaller ones to zero, and a zero target makes every edge Nmax
// segments (and a zero edge NaN). A run checks it in the units its kernels see, before it starts.
inline bool clipTargetFits(double l) { return float(l) >= std::numeric_limits<float>::min(); }

// Clip triangles for target edge length l: pre-splits where some edge needs more than `nmax` segments.
ClipTriangles buildClipTriangles(const Mesh& mesh, double l, int nmax);

// The same a parent at a time, parents in increasing order (as buildClipTriangles takes them): the
// split points of shared edges and the fresh weld ids are kept between calls, so the clip triangles come
// out as buildClipTriangles makes them, without holding all of them (a one-shot job's chunks).
class ClipTriangleBuilder {
 public:
  ClipTriangleBuilder(const Mesh& mesh, double l, int nmax);   // `mesh` outlives the builder
  ~ClipTriangleBuilder();
  void add(uint32_t parent, std::vector<ClipTriangle>& out);   // appends the parent's clip triangles
  size_t presplitParents() const { return presplitParents_; }

 private:
  struct Splits;
  const Mesh& mesh_;
  double l_;
  int nmax_;
  uint32_t nextWeld_ = 0;
  size_t made_ = 0, presplitParents_ = 0;
  std::unique_ptr<Splits> splits_;
  std::vector<ClipTriangle> work_;   // one parent's, reused
};

struct SubTriangleRecords {
  std::vector<uint32_t> headers;   // 4 per sub-triangle: parent, crease slot bits, 0, 0
  std::vector<double> records;     // SFFD_SUB_STRIDE * 4 per sub-triangle (kernels/common/layout.h)
  std::vector<DispatchTiming> timings;
  double wallMs = 0;
  size_t size() const { return headers.size() / 4; }
};

// Regular clipping on a backend: clip_count, the exclusive scan on the host, clip_write in chunks.
// `maxChunk` (not 0) caps the sub-triangles of one chunk, to test chunking.
SubTriangleRecords regularClip(Backend& backend, const PreparedMesh& mesh, const PnOutput& pn, const ClipTriangles& clip,
                               double l, KernelVariant variant, size_t maxChunk = 0);

// Records of sub-triangles given by their parent sites (knot-box clipping), on the host (clip_sites.h).
SubTriangleRecords recordsFromSubTriangles(const PreparedMesh& mesh, const PnOutput& pn,
                                           const std::vector<SubTriangle>& subs, KernelVariant variant);
// The same where `subs` have parents in [firstParent, + parents) only and `pnRecords` holds those parents'
// PN records (SFFD_PN_STRIDE real4 each, from firstParent's): what a streamed chunk has.
SubTriangleRecords recordsFromSubTriangles(const PreparedMesh& mesh, std::span<const double> pnRecords, size_t firstParent,
                                           size_t parents, const std::vector<SubTriangle>& subs, KernelVariant variant);

// Device inputs of the clip kernels (layout.h): the clip triangles packed as headers (8 uint each) and
// reals (SFFD_CLIP_REAL_STRIDE real4 each), and the split-pattern table as uint words (packedTable).
struct PackedClip {
  std::vector<uint32_t> headers;
  std::vector<double> reals;
};
PackedClip packClip(const ClipTriangles& clip);
PackedClip packClip(const ClipTriangles& clip, size_t first, size_t last);   // clip triangles [first, last)
// The split-pattern table as the clip kernels read it, the first section of their words: the patterns
// (4 words each), from vertexWord the vertices (a uvec4: lambda's bits, edge | step << 16), from
// triangleWord the triangles' 16-bit local indices two to a word; wordCount words in all. Those are the
// bytes of the compiled-in arrays (split_pattern_table.h) on a little-endian host, so uploadPackedTable
// copies them from there: nothing is packed at run time (4 MB at Nmax 24, once a process) nor copied
// through a vector first.
struct PackedTable {
  uint32_t nmax = 0, vertexWord = 0, triangleWord = 0, wordCount = 0;
};
PackedTable packedTableOf(const SplitPatternTable& table);
const PackedTable& packedTable();   // the compiled-in table's (splitPatternTable())
// Into words [0, wordCount) of `words`: the compiled-in table, or another (a test's).
void uploadPackedTable(Backend& backend, BufferId words, const SplitPatternTable& table = splitPatternTable());

// The clip kernels' two input ranges (layout.h, SFFD_BINDING_CLIP_REALS and SFFD_BINDING_CLIP_WORDS) of
// one pre-compute chunk: all the vertices, the chunk's parents [firstParent, + parents) and their clip
// triangles [firstClip, + clips); where each section begins, in real4 elements and in words, each at a
// multiple of SFFD_SECTION_ALIGN bytes. The one place that lays them out; clipRealRange and
// uploadClipWords fill them.
struct ClipRanges {
  uint64_t firstParent = 0, parents = 0, firstClip = 0, clips = 0;
  uint64_t normals = 0, slotNormals = 0, pn = 0, clipReals = 0, realElements = 0;
  uint64_t triangles = 0, clipHeaders = 0, counts = 0, words = 0;
  size_t realSize = 4;
  uint64_t byteOf(uint64_t element) const { return element * 4 * realSize; }   // of a real4 element
  void name(gpu::ClipParams& params) const;   // range.z, range.w, sections, words
};
ClipRanges clipRanges(const PreparedMesh& mesh, size_t clipTriangles, size_t realSize);   // the whole mesh, one chunk
ClipRanges clipRanges(uint64_t vertices, uint64_t firstParent, uint64_t parents, uint64_t firstClip, uint64_t clips,
                      size_t realSize);
// The reals' range (the PN records' section zero without `pnRecords`, the whole mesh's: the caller's
// pn_triangles writes it), in the kernel's reals (float or double: no wider copy of a large range),
// and uploadClipWords the words'; `clip` holds the chunk's clip triangles (packClip).
template <class Real>
std::vector<Real> clipRealRange(const ClipRanges& r, const PreparedMesh& mesh, const std::vector<double>* pnRecords,
                                  const PackedClip& clip);
// Its two parts, which every chunk of a mesh shares and which are the chunk's own: the vertices' section
// (elements [0, 2 * vertices); the rest of [0, r.slotNormals) is padding), and from element r.slotNormals
// on the parents' and clip triangles' sections, written at `out` (room for 4 * (r.realElements -
// r.slotNormals) reals, zero-filled).
template <class Real>
void writeClipVertexSection(const PreparedMesh& mesh, Real* out);
template <class Real>
void writeClipParentSections(const ClipRanges& r, const PreparedMesh& mesh, const std::vector<double>* pnRecords,
                             const PackedClip& clip, Real* out);
// The words' range into `words` (r.words words): the table (uploadPackedTable) where `withTable` (a buffer
// that already holds it, kept from the chunk before, skips it), then the chunk's own sections from
// r.triangles on: its parents' triangles, its clip triangles' headers and their counts (zero).
void uploadClipWords(Backend& backend, BufferId words, const ClipRanges& r, const PreparedMesh& mesh,
                     const PackedClip& clip, bool withTable);

struct CpuKernelArgs;
namespace cpu {
// CPU entries of kernels clip_count and clip_write (clip_sites_cpu.cpp).
void clipCount(const CpuKernelArgs& args, uint64_t first, uint64_t last);
void clipWrite(const CpuKernelArgs& args, uint64_t first, uint64_t last);
}  // namespace cpu

}  // namespace sffd
