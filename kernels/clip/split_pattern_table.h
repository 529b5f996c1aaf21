// Crack-free split-pattern table for the improved smooth FFD of Lu & Feng (METHOD.md section 4,
// "Improved clipping: crack-free split-pattern table"). A triangle whose edges get n_e segments is
// split by the pattern of its sorted counts a <= b <= c; every boundary vertex lies at exactly t/n
// on its edge, so two triangles sharing an edge produce the same vertices there (no T-junctions).
//
// Plain data, laid out for a GPU (docs/SPLIT_PATTERNS.md): a dense entry array indexed by
// splitPatternKey, one flat vertex array (16-byte records) and one flat index array (3 local
// indices per triangle). tools/split_pattern_gen.cpp writes the arrays at build time; they are
// compiled into sffd_core, nothing is read from a path at run time.
#pragma once
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

namespace sffd {

inline constexpr uint8_t kSplitEdgeInterior = 3;

// One pattern vertex. Read on the GPU as a uvec4: xyz = floatBitsToUint(lambda),
// w = edge | step << 16.
struct SplitPatternVertex {
  float lambda[3];  // barycentrics w.r.t. the canonical corners C0, C1, C2
  uint8_t edge;     // 0: C0C1 (a segments), 1: C1C2 (b), 2: C2C0 (c), 3: interior; corner Ce is edge e, step 0
  uint8_t pad;
  uint16_t step;    // t, 0..n-1 from the edge's first corner; 0 for interior vertices
};
static_assert(sizeof(SplitPatternVertex) == 16 && offsetof(SplitPatternVertex, step) == 14);

// Within a pattern the vertices come in this order: edge 0 (steps 0..a-1), edge 1 (0..b-1),
// edge 2 (0..c-1), then the interior ones; so boundary vertex (e, t) has local index
// {0, a, a + b}[e] + t. Triangles are CCW in the canonical frame.
struct SplitPattern {
  uint32_t firstVertex, vertexCount, firstTriangle, triangleCount;
};

// Index into the dense entry array for sorted counts 1 <= a <= b <= c <= nmax.
constexpr uint32_t splitPatternKey(int nmax, int a, int b, int c) {
  return (uint32_t(a - 1) * uint32_t(nmax) + uint32_t(b - 1)) * uint32_t(nmax) + uint32_t(c - 1);
}

class SplitPatternTable {
 public:
  constexpr SplitPatternTable(int nmax, std::span<const SplitPattern> patterns,
                              std::span<const SplitPatternVertex> vertices, std::span<const uint16_t> triangles)
      : nmax_(nmax), patterns_(patterns), vertices_(vertices), triangles_(triangles) {}

  int nmax() const { return nmax_; }
  // The entry for sorted counts; an empty one (counts 0) for unsorted, invalid (c > a + b) or
  // out-of-range counts.
  const SplitPattern& pattern(int a, int b, int c) const;
  std::span<const SplitPatternVertex> vertices(const SplitPattern& p) const {
    return vertices_.subspan(p.firstVertex, p.vertexCount);
  }
  std::span<const uint16_t> triangles(const SplitPattern& p) const {
    return triangles_.subspan(size_t(p.firstTriangle) * 3, size_t(p.triangleCount) * 3);
  }

  // The flat arrays, as uploaded to storage buffers.
  std::span<const SplitPattern> patterns() const { return patterns_; }  // nmax^3, by splitPatternKey
  std::span<const SplitPatternVertex> vertices() const { return vertices_; }
  std::span<const uint16_t> triangles() const { return triangles_; }  // 3 local indices per triangle

 private:
  int nmax_;
  std::span<const SplitPattern> patterns_;
  std::span<const SplitPatternVertex> vertices_;
  std::span<const uint16_t> triangles_;
};

// The table compiled into the library (Nmax = the CMake cache variable SFFD_SPLIT_NMAX).
const SplitPatternTable& splitPatternTable();

// Barycentric pair (first corner, last corner) of the point t/n along an edge, 0 <= t <= n. The
// larger weight is t/n or 1 - t/n rounded once to float; the smaller is 1 minus it, exact by
// Sterbenz. So the pair sums to exactly 1 (the point is on the edge's line in any frame), and
// walking the edge from its other end gives the same pair swapped: both triangles of a shared edge
// store the same bits. The generator and the tests use this; a GPU kernel reads the table instead
// of recomputing it (GPU division is not correctly rounded).
inline std::array<float, 2> splitEdgeLambda(int t, int n) {
  bool firstLarger = 2 * t <= n;
  float large = float(firstLarger ? n - t : t) / float(n);
  float small = 1.0f - large;
  return firstLarger ? std::array<float, 2>{large, small} : std::array<float, 2>{small, large};
}

// The canonical triangle of counts a <= b <= c (edge length l = 1): C0 = (0, 0), C1 = (a, 0),
// |C1C2| = b, |C2C0| = c, C2 above the x axis; a flat triple (a + b = c) gets a and b widened
// by 0.05.
inline std::array<std::array<double, 2>, 3> splitCanonicalTriangle(int a, int b, int c) {
  double aa = a, bb = b, cc = c;
  if (aa + bb - cc < 1e-9) {
    aa += 0.05;
    bb += 0.05;
  }
  double x = (aa * aa + cc * cc - bb * bb) / (2 * aa);
  return {{{0.0, 0.0}, {aa, 0.0}, {x, std::sqrt(cc * cc - x * x)}}};
}

}  // namespace sffd
