// Exact changes of a lattice's basis that keep its volume: knot insertion (W. Boehm, "Inserting new
// knots into B-spline curves", Computer-Aided Design 12(4), 1980) and degree elevation (the elevated
// spline space with every knot's multiplicity raised by the same amount contains the old one; L. Piegl
// and W. Tiller, The NURBS Book, 2nd ed., section 5.5). Both are a linear map per axis from the old
// control points to the new ones, applied along each axis of the tensor-product net in turn.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <sffd/error.h>

#include "core/job_budget.h"
#include "model/lattice.h"

namespace sffd {
namespace {

// The most control points along one axis these operations make (their maps are dense: count^2 each).
constexpr int64_t kMaxAxisCount = 1024;
constexpr const char* kRefineLimitName = "the memoryLimit of refineLattice or elevateLattice";

// Rows: new control points, columns: old ones (P_new[r] = sum_c M[r][c] P_old[c]).
using AxisMap = std::vector<std::vector<double>>;

// The index s of the knot span [U[s], U[s+1]) holding t, for a basis of `count` functions of degree p;
// the domain's right end belongs to the last non-empty span.
int findSpan(const std::vector<double>& U, int count, int p, double t) {
  if (t >= U[count]) {
    int s = count - 1;
    while (s > p && U[s] == U[s + 1]) --s;
    return s;
  }
  int s = int(std::upper_bound(U.begin() + p, U.begin() + count, t) - U.begin()) - 1;
  return std::max(s, p);
}

// Values of the p+1 basis functions N_{s-p..s} that are non-zero on span s at t (The NURBS Book A2.2).
std::vector<double> basisFunctions(const std::vector<double>& U, int s, int p, double t) {
  std::vector<double> N(p + 1, 0.0), left(p + 1), right(p + 1);
  N[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - U[s + 1 - j];
    right[j] = U[s + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double temp = N[r] / (right[r + 1] + left[j - r]);
      N[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
  return N;
}

// Solves A X = B for X (A n x n, B n x m) by Gaussian elimination with partial pivoting.
AxisMap solve(AxisMap A, AxisMap B) {
  const size_t n = A.size();
  for (size_t c = 0; c < n; ++c) {
    size_t pivot = c;
    for (size_t r = c + 1; r < n; ++r)
      if (std::abs(A[r][c]) > std::abs(A[pivot][c])) pivot = r;
    std::swap(A[c], A[pivot]);
    std::swap(B[c], B[pivot]);
    for (size_t r = c + 1; r < n; ++r) {
      const double f = A[r][c] / A[c][c];
      if (f == 0.0) continue;
      for (size_t k = c; k < n; ++k) A[r][k] -= f * A[c][k];
      for (size_t k = 0; k < B[r].size(); ++k) B[r][k] -= f * B[c][k];
    }
  }
  for (size_t c = n; c-- > 0;) {
    for (size_t r = c + 1; r < n; ++r)
      for (size_t k = 0; k < B[c].size(); ++k) B[c][k] -= A[c][r] * B[r][k];
    for (double& v : B[c]) v /= A[c][c];
  }
  return B;
}

// Knot insertion: every non-empty span of the domain split into `parts` equal spans.
AxisMap refineAxis(std::vector<double>& knots, int p, int count, int parts) {
  AxisMap P(count, std::vector<double>(count, 0.0));
  for (int i = 0; i < count; ++i) P[i][i] = 1.0;
  if (parts <= 1) return P;
  std::vector<double> inserted;
  for (int s = p; s < count; ++s) {
    const double a = knots[s], b = knots[s + 1];
    if (b > a)
      for (int q = 1; q < parts; ++q) inserted.push_back(a + (b - a) * q / parts);
  }
  for (double t : inserted) insertKnot(knots, P, p, t);
  return P;
}

// Degree elevation by `by`: the clamped knot vector over the same domain with every interior knot's
// multiplicity raised by `by`; the new control points interpolate the old volume at the new basis'
// Greville abscissae (Schoenberg-Whitney holds there, so the collocation matrix is invertible, and the
// old function lies in the new space, so the interpolant is the function itself).
AxisMap elevateAxis(std::vector<double>& knots, int& p, int count, int by, const std::string& source, char axis) {
  const int q = p + by;
  const double lo = knots[p], hi = knots[count];
  std::vector<double> U(q + 1, lo);
  for (int s = p + 1; s < count;) {
    int m = 1;
    while (s + m < count && knots[s + m] == knots[s]) ++m;
    if (m > p)
      throw inputError(source, 0, std::string("knot ") + axis + " = " + std::to_string(knots[s]) + " has multiplicity " +
                                      std::to_string(m) + " > degree (a discontinuous lattice): cannot elevate it");
    U.insert(U.end(), size_t(m + by), knots[s]);
    s += m;
  }
  U.insert(U.end(), size_t(q + 1), hi);
  const int newCount = int(U.size()) - q - 1;
  const std::vector<double> tau = grevilleAbscissae(U, q);
  AxisMap A(newCount, std::vector<double>(newCount, 0.0)), B(newCount, std::vector<double>(count, 0.0));
  for (int j = 0; j < newCount; ++j) {
    const int sn = findSpan(U, newCount, q, tau[j]);
    const std::vector<double> Nn = basisFunctions(U, sn, q, tau[j]);
    for (int r = 0; r <= q; ++r) A[j][sn - q + r] = Nn[r];
    const int so = findSpan(knots, count, p, tau[j]);
    const std::vector<double> No = basisFunctions(knots, so, p, tau[j]);
    for (int r = 0; r <= p; ++r) B[j][so - p + r] = No[r];
  }
  knots = std::move(U);
  p = q;
  return solve(std::move(A), std::move(B));
}

// Applies one map per axis to the control net (counts change to the maps' row counts), within
// `memoryLimit`: the caller's lattice and the nets before and after one axis are alive at once.
void applyAxisMaps(Lattice& L, const std::array<AxisMap, 3>& maps, const std::string& source, uint64_t memoryLimit) {
  const int64_t points = int64_t(maps[0].size()) * int64_t(maps[1].size()) * int64_t(maps[2].size());
  if (points > int64_t(kMaxLatticeControlPoints))
    throw inputError(source, 0, "the lattice would have " + std::to_string(points) + " control points; at most " +
                                    std::to_string(kMaxLatticeControlPoints));
  uint64_t net = L.controlPoints.size(), peak = 0;
  std::array<uint64_t, 3> counts = {uint64_t(L.counts[0]), uint64_t(L.counts[1]), uint64_t(L.counts[2])};
  for (int a = 0; a < 3; ++a) {
    counts[a] = maps[a].size();
    const uint64_t next = counts[0] * counts[1] * counts[2];
    peak = std::max(peak, net + next);
    net = next;
  }
  const uint64_t bytes = (L.controlPoints.size() + peak) * sizeof(glm::dvec3);
  checkHostBytesFit(bytes, memoryLimit, kRefineLimitName,
                    source + ": the lattice of " + std::to_string(points) + " control points needs",
                    "refine or elevate less");
  std::array<int, 3> n = L.counts;
  std::vector<glm::dvec3> cur = std::move(L.controlPoints);
  for (int a = 0; a < 3; ++a) {
    std::array<int, 3> m = n;
    m[a] = int(maps[a].size());
    std::vector<glm::dvec3> next(size_t(m[0]) * m[1] * m[2], glm::dvec3(0.0));
    for (int i = 0; i < m[0]; ++i)
      for (int j = 0; j < m[1]; ++j)
        for (int k = 0; k < m[2]; ++k) {
          const int out[3] = {i, j, k};
          const auto& row = maps[a][size_t(out[a])];
          glm::dvec3 s(0.0);
          for (int c = 0; c < n[a]; ++c) {
            if (row[size_t(c)] == 0.0) continue;
            int in[3] = {i, j, k};
            in[a] = c;
            s += row[size_t(c)] * cur[(size_t(in[0]) * n[1] + in[1]) * n[2] + in[2]];
          }
          next[(size_t(i) * m[1] + j) * m[2] + k] = s;
        }
    cur = std::move(next);
    n = m;
  }
  L.counts = n;
  L.controlPoints = std::move(cur);
}

}  // namespace

Lattice refineLattice(const Lattice& lattice, std::array<int, 3> parts, const std::string& source, uint64_t memoryLimit) {
  validateLattice(lattice, source);
  Lattice L = lattice;
  std::array<AxisMap, 3> maps;
  for (int a = 0; a < 3; ++a) {
    if (parts[a] < 1 || parts[a] > 64) throw inputError(source, 0, "refine: knot spans are split into 1..64 parts");
    int spans = 0;
    for (int s = L.degree[a]; s < L.counts[a]; ++s) spans += L.knots[a][s + 1] > L.knots[a][s];
    if (L.counts[a] + int64_t(parts[a] - 1) * spans > kMaxAxisCount)
      throw inputError(source, 0, "refine: axis " + std::string(1, "uvw"[a]) + " would have " +
                                      std::to_string(L.counts[a] + int64_t(parts[a] - 1) * spans) +
                                      " control points; at most " + std::to_string(kMaxAxisCount));
    maps[a] = refineAxis(L.knots[a], L.degree[a], L.counts[a], parts[a]);
  }
  applyAxisMaps(L, maps, source, memoryLimit);
  validateLattice(L, source);
  return L;
}

Lattice elevateLattice(const Lattice& lattice, std::array<int, 3> by, const std::string& source, uint64_t memoryLimit) {
  validateLattice(lattice, source);
  Lattice L = lattice;
  std::array<AxisMap, 3> maps;
  for (int a = 0; a < 3; ++a) {
    if (by[a] < 0 || L.degree[a] + by[a] > 5)
      throw inputError(source, 0, "elevate: degrees stay within 1..5 (axis " + std::string(1, "uvw"[a]) + " has degree " +
                                      std::to_string(L.degree[a]) + ")");
    if (by[a] == 0) {
      maps[a] = refineAxis(L.knots[a], L.degree[a], L.counts[a], 1);   // the identity
      continue;
    }
    maps[a] = elevateAxis(L.knots[a], L.degree[a], L.counts[a], by[a], source, "uvw"[a]);
  }
  applyAxisMaps(L, maps, source, memoryLimit);
  validateLattice(L, source);
  return L;
}

}  // namespace sffd
