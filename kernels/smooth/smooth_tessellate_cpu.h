// Step 6 of the deform kernels' C++ twin: smoothTessellate (smooth_deform.glsl), a sub-triangle's cubic
// patch and its normal patch at level L. The kernel computes each vertex's weights and then its sums; here a
// level's weights are computed once, by the kernel's own functions (so the same bits), and the sums run
// across eight vertices in the lanes of one vector, each lane doing one vertex's operations in the kernel's
// order: the same values, no idle lane (docs/performance/stages.md, "The CPU device's AVX2 copies").
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include "kernels/common/rvec.h"
#include "kernels/pn/pn_eval.h"

namespace sffd {

template <class Real>
class SmoothTessellation {
 public:
  static constexpr int kLanes = 8;

  explicit SmoothTessellation(int level) : L_(level), nv_((level + 1) * (level + 2) / 2) {
    // Edge a runs from corner a to a + 1, its vertices s = 1..L-1 steps from corner a (the kernel's order);
    // the weights of s steps forward and of L - s steps (the edge evaluated from its other corner).
    for (int a = 0; a < 3; ++a)
      for (int s = 1; s < L_; ++s) {
        int r = a == 0 ? s : (a == 1 ? L_ : L_ - s), t = a == 0 ? 0 : (a == 1 ? s : L_ - s);
        edgeVertex_.push_back(uint32_t(r * (r + 1) / 2 + t));
      }
    const int edgeGroups = groupsOf(L_ - 1);
    for (auto* table : {&edgeForward_, &edgeReversed_}) table->assign(size_t(edgeGroups) * 4 * kLanes, Real(0));
    for (int s = 1; s < L_; ++s) {
      Real w[4], wr[4];
      pnEdgeWeights(Real(s) / Real(L_), w);
      pnEdgeWeights(Real(L_ - s) / Real(L_), wr);
      for (int q = 0; q < 4; ++q) edgeForward_[at(s - 1, q, 4)] = w[q], edgeReversed_[at(s - 1, q, 4)] = wr[q];
    }
    for (int r = 2; r < L_; ++r)
      for (int t = 1; t < r; ++t) {
        const int i = int(innerVertex_.size());
        innerVertex_.push_back(uint32_t(r * (r + 1) / 2 + t));
        innerWeights_.resize(size_t(groupsOf(i + 1)) * 10 * kLanes, Real(0));
        Real w[10];
        pnCubicWeights(RVec3<Real>{Real(L_ - r), Real(r - t), Real(t)} / Real(L_), w);
        for (int q = 0; q < 10; ++q) innerWeights_[at(i, q, 10)] = w[q];
      }
  }

  int vertices() const { return nv_; }

  // Writes the nv positions, then the nv normals, 4 reals each (w = 0), to out.
  void run(const RVec3<Real> cp[10], const RVec3<Real> ncp[10], Real* out) const {
    const int lastRow = L_ * (L_ + 1) / 2, cornerVertex[3] = {0, lastRow, lastRow + L_};
    for (int c = 0; c < 3; ++c) {
      put(out + 4 * cornerVertex[c], cp[kCornerControlPoint[c]]);
      put(out + 4 * (nv_ + cornerVertex[c]), snormalize(ncp[kCornerControlPoint[c]]));
    }
    // Edge a's cubic through corner a, the control points of slots 2a+1 and 2a+2 and corner a+1 (0 1 3 6,
    // 6 7 8 9, 9 5 2 0); evaluated from the lexicographically smaller corner, so both patches of an edge
    // agree bit for bit.
    for (int a = 0; a < 3; ++a) {
      int q[4] = {kCornerControlPoint[a], kSlotControlPoint[2 * a + 1], kSlotControlPoint[(2 * a + 2) % 6],
                  kCornerControlPoint[(a + 1) % 3]};
      const bool reversed = lexLess(cp[q[3]], cp[q[0]]);
      if (reversed) std::swap(q[0], q[3]), std::swap(q[1], q[2]);
      const Real* table = reversed ? edgeReversed_.data() : edgeForward_.data();
      const uint32_t* vertex = edgeVertex_.data() + size_t(a) * (L_ - 1);
      for (int g = 0; g * kLanes < L_ - 1; ++g) {
        V w[4];
        for (int k = 0; k < 4; ++k) std::memcpy(&w[k], &table[at(g * kLanes, k, 4)], sizeof(V));
        // pnEdgeCurve's sums, x, y, z of the position then of the normal.
        V sum[6];
        for (int c = 0; c < 6; ++c) {
          const RVec3<Real>* p = c < 3 ? cp : ncp;
          const int axis = c % 3;
          sum[c] = ((p[q[0]][axis] * w[0] + p[q[1]][axis] * w[1]) + p[q[2]][axis] * w[2]) + p[q[3]][axis] * w[3];
        }
        store(sum, vertex + g * kLanes, std::min(kLanes, L_ - 1 - g * kLanes), out);
      }
    }
    const int inner = int(innerVertex_.size());
    for (int g = 0; g * kLanes < inner; ++g) {
      V sum[6] = {};
      for (int k = 0; k < 10; ++k) {
        V w;
        std::memcpy(&w, &innerWeights_[at(g * kLanes, k, 10)], sizeof(V));
        for (int c = 0; c < 3; ++c) sum[c] = sum[c] + cp[k][c] * w, sum[3 + c] = sum[3 + c] + ncp[k][c] * w;
      }
      store(sum, innerVertex_.data() + size_t(g) * kLanes, std::min(kLanes, inner - g * kLanes), out);
    }
  }

 private:
  using V = typename LanesOf<Real, kLanes>::type;

  static int groupsOf(int n) { return (n + kLanes - 1) / kLanes; }
  // Weight k of the table's vertex i: grouped kLanes vertices a group, k-major within a group.
  static size_t at(int i, int k, int weights) { return (size_t(i / kLanes) * weights + k) * kLanes + i % kLanes; }
  static void put(Real* o, RVec3<Real> v) { o[0] = v.x, o[1] = v.y, o[2] = v.z, o[3] = 0; }

  // The normal's snormalize lane by lane (a lane without a direction keeps its sums), then `count` vertices
  // stored: sum[0..2] the positions' x, y, z, sum[3..5] the normals'.
  void store(V (&sum)[6], const uint32_t* vertex, int count, Real* out) const {
    const V len2 = (sum[3] * sum[3] + sum[4] * sum[4]) + sum[5] * sum[5];
    V len = {};
    for (int l = 0; l < kLanes; ++l) len[l] = std::sqrt(len2[l]);
    const auto direction = len2 >= Real(SFFD_MIN_DIRECTION_LENGTH2);   // hasDirection, lane by lane
    for (int c = 3; c < 6; ++c) sum[c] = direction ? sum[c] / len : sum[c];
    for (int l = 0; l < count; ++l) {
      put(out + 4 * vertex[l], {sum[0][l], sum[1][l], sum[2][l]});
      put(out + 4 * (nv_ + vertex[l]), {sum[3][l], sum[4][l], sum[5][l]});
    }
  }

  int L_, nv_;
  std::vector<uint32_t> edgeVertex_, innerVertex_;
  std::vector<Real> edgeForward_, edgeReversed_, innerWeights_;
};

}  // namespace sffd
