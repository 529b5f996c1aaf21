// B-spline lattice model: knots, Greville identity, validation and per-knot-box Bezier extraction
// by Boehm knot insertion (METHOD.md 1.1-1.2; Boehm, "Inserting new knots into B-spline curves", 1980).
#include "model/lattice.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <sffd/error.h>

namespace sffd {

std::vector<double> clampedUniformKnots(int count, int degree, double lo, double hi) {
  // What validateLattice allows, so that a negative or huge count makes no vector of it.
  if (degree < 1 || degree > 5 || count <= degree || count > kMaxLatticeAxisCount)
    throw inputError("clampedUniformKnots", 0, "a knot vector is for degree 1..5 and " + std::to_string(degree) + " + 1.." +
                                                   std::to_string(kMaxLatticeAxisCount) + " control points, not degree " +
                                                   std::to_string(degree) + " with " + std::to_string(count));
  std::vector<double> k;
  int spans = count - degree;
  for (int i = 0; i <= degree; ++i) k.push_back(lo);
  for (int i = 1; i < spans; ++i) k.push_back(lo + (hi - lo) * double(i) / spans);
  for (int i = 0; i <= degree; ++i) k.push_back(hi);
  return k;
}

std::vector<double> grevilleAbscissae(const std::vector<double>& knots, int degree) {
  std::vector<double> xi(knots.size() - degree - 1);
  for (size_t i = 0; i < xi.size(); ++i) {
    double s = 0;
    for (int j = 1; j <= degree; ++j) s += knots[i + j];
    xi[i] = s / degree;
  }
  return xi;
}

glm::dmat3 cofactor(const glm::dmat3& m) {
  // Columns of cof(M) = det(M) M^{-T}: cross products of the other two columns.
  return glm::dmat3(glm::cross(m[1], m[2]), glm::cross(m[2], m[0]), glm::cross(m[0], m[1]));
}

namespace {

// The identity control points of a lattice whose structure is valid.
void identityPoints(Lattice& L) {
  std::array<std::vector<double>, 3> xi;
  for (int a = 0; a < 3; ++a) xi[a] = grevilleAbscissae(L.knots[a], L.degree[a]);
  glm::dmat3 inv = glm::inverse(L.frameLinear);
  L.controlPoints.resize(L.pointCount());
  for (int i = 0; i < L.counts[0]; ++i)
    for (int j = 0; j < L.counts[1]; ++j)
      for (int k = 0; k < L.counts[2]; ++k)
        L.controlPoints[L.index(i, j, k)] = inv * (glm::dvec3(xi[0][i], xi[1][j], xi[2][k]) - L.frameOffset);
}

// makeIdentityLattice, its errors naming `source`.
Lattice identityLattice(glm::dvec3 lo, glm::dvec3 hi, std::array<int, 3> counts, std::array<int, 3> degree,
                        const std::string& source) {
  size_t points = 1;
  for (int a = 0; a < 3; ++a) {
    if (counts[a] < 1 || counts[a] > kMaxLatticeAxisCount)
      throw inputError(source, 0, "a lattice has 1.." + std::to_string(kMaxLatticeAxisCount) + " control points an axis, not " +
                                      std::to_string(counts[a]));
    points *= size_t(counts[a]);
  }
  if (points > kMaxLatticeControlPoints)
    throw inputError(source, 0, "a lattice of " + std::to_string(points) + " control points is too large (at most " +
                                    std::to_string(kMaxLatticeControlPoints) + ")");
  Lattice L;
  L.counts = counts;
  L.degree = degree;
  // Degrees and counts first: knots made for a degree outside 1..5 or too few points would be refused for
  // their length, a message about something the caller did not give.
  for (int a = 0; a < 3; ++a)
    if (degree[a] >= 1 && degree[a] <= 5 && counts[a] > degree[a]) L.knots[a] = clampedUniformKnots(counts[a], degree[a], lo[a], hi[a]);
  validateLatticeStructure(L, source);   // also a box of no size or of non-finite corners
  identityPoints(L);
  return L;
}

}  // namespace

void setIdentityControlPoints(Lattice& L) {
  validateLatticeStructure(L, "setIdentityControlPoints");   // its knots and frame are all it reads
  identityPoints(L);
}

Lattice makeIdentityLattice(glm::dvec3 lo, glm::dvec3 hi, std::array<int, 3> counts, std::array<int, 3> degree) {
  return identityLattice(lo, hi, counts, degree, "makeIdentityLattice");
}

Lattice fitLattice(const Mesh& mesh, std::array<int, 3> counts, std::array<int, 3> degree, double margin) {
  if (mesh.positions.empty()) throw Error(ErrorKind::Input, "fitLattice: the mesh has no vertices");
  if (!(margin >= 0) || !std::isfinite(margin)) throw Error(ErrorKind::Input, "fitLattice: the margin must be a finite number >= 0");
  for (int a = 0; a < 3; ++a) {
    if (degree[a] < 1 || degree[a] > 5) throw Error(ErrorKind::Input, "fitLattice: degrees must be in 1..5");
    if (counts[a] <= degree[a]) throw Error(ErrorKind::Input, "fitLattice: counts must exceed the degree on every axis");
  }
  glm::dvec3 lo = mesh.positions[0], hi = lo;
  for (const glm::dvec3& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  // A margin keeps every vertex strictly inside and gives a flat mesh a non-empty box; a mesh at one point
  // gets a box of 1e-12 of its distance from the origin (at least 1e-12), so that its sides stay apart
  // there too. Only such a mesh: a mesh smaller than 1e-12 got that box too, and a preset on it was
  // another deformation than on the mesh at any other size.
  const double far = std::max({1.0, std::abs(lo.x), std::abs(lo.y), std::abs(lo.z), std::abs(hi.x), std::abs(hi.y), std::abs(hi.z)});
  const double size = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  const double extent = size > 0 ? size : 1e-12 * far;
  lo -= glm::dvec3(margin * extent);
  hi += glm::dvec3(margin * extent);
  Lattice L = identityLattice(lo, hi, counts, degree, "fitLattice");
  // Said here, not by the next user of the lattice: a box of a non-finite vertex or past the range of doubles
  // (a huge margin), or one without size (a flat mesh with no margin).
  validateLattice(L, "fitLattice");
  return L;
}

void validateLattice(const Lattice& L, const std::string& source) {
  validateLatticeStructure(L, source);
  if (L.controlPoints.size() != L.pointCount())
    throw inputError(source, 0, "lattice has " + std::to_string(L.controlPoints.size()) + " control points; " +
                                    std::to_string(L.pointCount()) + " expected");
  for (size_t i = 0; i < L.controlPoints.size(); ++i) {
    const glm::dvec3& p = L.controlPoints[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw inputError(source, 0, "control point " + std::to_string(i) + " is not finite");
  }
}

void validateLatticeStructure(const Lattice& L, const std::string& source) {
  static const char* axis = "uvw";
  for (int a = 0; a < 3; ++a) {
    std::string ax(1, axis[a]);
    if (L.degree[a] < 1 || L.degree[a] > 5)
      throw inputError(source, 0, "degree " + std::to_string(L.degree[a]) + " on axis " + ax + " is outside 1..5");
    if (L.counts[a] <= L.degree[a])
      throw inputError(source, 0, "axis " + ax + " has " + std::to_string(L.counts[a]) +
                                      " control points; a degree-" + std::to_string(L.degree[a]) + " axis needs at least " +
                                      std::to_string(L.degree[a] + 1));
    if (L.counts[a] > kMaxLatticeAxisCount)
      throw inputError(source, 0, "axis " + ax + " has more than " + std::to_string(kMaxLatticeAxisCount) + " control points");
    const auto& k = L.knots[a];
    if (k.size() != size_t(L.counts[a] + L.degree[a] + 1))
      throw inputError(source, 0, "knot vector " + ax + " has " + std::to_string(k.size()) + " values; counts+degree+1 = " +
                                      std::to_string(L.counts[a] + L.degree[a] + 1) + " needed");
    for (size_t i = 0; i < k.size(); ++i) {
      if (!std::isfinite(k[i])) throw inputError(source, 0, "knot vector " + ax + " has a non-finite value");
      if (i > 0 && k[i] < k[i - 1]) throw inputError(source, 0, "knot vector " + ax + " is not non-decreasing");
    }
    if (!(L.domainHi(a) > L.domainLo(a)))
      throw inputError(source, 0, "axis " + ax + " has an empty domain (zero-size box or repeated knots)");
  }
  if (L.pointCount() > kMaxLatticeControlPoints)
    throw inputError(source, 0, "lattice of " + std::to_string(L.pointCount()) + " control points is too large (at most " +
                                    std::to_string(kMaxLatticeControlPoints) + ")");
  double det = glm::determinant(L.frameLinear);
  if (!std::isfinite(det) || std::abs(det) < 1e-300) throw inputError(source, 0, "lattice frame is singular");
  if (!std::isfinite(L.frameOffset.x) || !std::isfinite(L.frameOffset.y) || !std::isfinite(L.frameOffset.z))
    throw inputError(source, 0, "lattice frame offset is not finite");
}

void insertKnot(std::vector<double>& U, std::vector<std::vector<double>>& P, int p, double t) {
  int k = int(std::upper_bound(U.begin(), U.end(), t) - U.begin()) - 1;   // last U[k] <= t
  int s = int(std::count(U.begin(), U.end(), t));
  size_t m = P.size();
  std::vector<std::vector<double>> Q(m + 1);
  for (int i = 0; i <= int(m); ++i) {
    if (i <= k - p) Q[i] = P[i];
    else if (i >= k - s + 1) Q[i] = P[i - 1];
    else {
      double alpha = (t - U[i]) / (U[i + p] - U[i]);
      Q[i].resize(P[i].size());
      for (size_t c = 0; c < P[i].size(); ++c) Q[i][c] = (1 - alpha) * P[i - 1][c] + alpha * P[i][c];
    }
  }
  U.insert(U.begin() + k + 1, t);
  P = std::move(Q);
}

namespace {

struct AxisExtraction {
  std::vector<double> breaks;
  // rows: span*(p+1)+r, columns: original control points
  std::vector<std::vector<double>> matrix;
  // Per row, the range [first, last) of its non-zero columns (at most p+1), so that a knot box costs
  // O((p+1)^3) and not O(counts^3): without it a 64^3 lattice took minutes and 256^3 never ended.
  std::vector<std::pair<int, int>> nonzero;
  // The union of the ranges of the p+1 rows of each span.
  std::pair<int, int> spanRange(int span, int p) const {
    std::pair<int, int> r{nonzero[size_t(span) * (p + 1)]};
    for (int k = 1; k <= p; ++k) {
      r.first = std::min(r.first, nonzero[size_t(span) * (p + 1) + k].first);
      r.second = std::max(r.second, nonzero[size_t(span) * (p + 1) + k].second);
    }
    return r;
  }
};

AxisExtraction extractAxis(const std::vector<double>& knots, int p, int count) {
  std::vector<double> U = knots;
  std::vector<std::vector<double>> P(count, std::vector<double>(count, 0.0));
  for (int i = 0; i < count; ++i) P[i][i] = 1.0;
  double lo = knots[p], hi = knots[count];
  std::vector<double> distinct;
  for (double u : knots)
    if (u >= lo && u <= hi && (distinct.empty() || u != distinct.back())) distinct.push_back(u);
  for (double t : distinct)
    while (std::count(U.begin(), U.end(), t) < p) insertKnot(U, P, p, t);
  AxisExtraction ax;
  ax.breaks = distinct;
  for (size_t sp = 0; sp + 1 < distinct.size(); ++sp) {
    // The span [a, b): last index i with U[i] == a; its Bezier points are P[i-p .. i].
    int i = int(std::upper_bound(U.begin(), U.end(), distinct[sp]) - U.begin()) - 1;
    for (int r = 0; r <= p; ++r) ax.matrix.push_back(P[i - p + r]);
  }
  for (const auto& row : ax.matrix) {
    int first = 0, last = int(row.size());
    while (first < last && row[first] == 0) ++first;
    while (last > first && row[last - 1] == 0) --last;
    ax.nonzero.push_back({first, last});
  }
  return ax;
}

}  // namespace

LatticeBoxForm extractBoxForm(const Lattice& L) {
  LatticeBoxForm F;
  F.degree = L.degree;
  std::array<AxisExtraction, 3> ax;
  for (int a = 0; a < 3; ++a) {
    ax[a] = extractAxis(L.knots[a], L.degree[a], L.counts[a]);
    F.breaks[a] = ax[a].breaks;
    F.boxes[a] = int(ax[a].breaks.size()) - 1;
  }
  const int nu = L.degree[0] + 1, nv = L.degree[1] + 1, nw = L.degree[2] + 1;
  F.coeffs.assign(size_t(F.boxes[0]) * F.boxes[1] * F.boxes[2] * nu * nv * nw, glm::dvec3(0));
  // Contract one axis at a time: w, then v, then u, each over the non-zero columns of its rows only
  // (the sums run in the same order as over all columns, skipping exact zeros as before: the same bits).
  std::vector<glm::dvec3> tw, tv;
  for (int bu = 0; bu < F.boxes[0]; ++bu)
    for (int bv = 0; bv < F.boxes[1]; ++bv)
      for (int bw = 0; bw < F.boxes[2]; ++bw) {
        const auto [ia, ib] = ax[0].spanRange(bu, L.degree[0]);
        const auto [ja, jb] = ax[1].spanRange(bv, L.degree[1]);
        const int I = ib - ia, J = jb - ja;
        tw.assign(size_t(I) * J * nw, glm::dvec3(0));
        for (int i = ia; i < ib; ++i)
          for (int j = ja; j < jb; ++j)
            for (int r = 0; r < nw; ++r) {
              const auto& row = ax[2].matrix[bw * nw + r];
              const auto [k0, k1] = ax[2].nonzero[bw * nw + r];
              glm::dvec3 s(0);
              for (int k = k0; k < k1; ++k)
                if (row[k] != 0) s += row[k] * L.controlPoints[L.index(i, j, k)];
              tw[(size_t(i - ia) * J + (j - ja)) * nw + r] = s;
            }
        tv.assign(size_t(I) * nv * nw, glm::dvec3(0));
        for (int i = ia; i < ib; ++i)
          for (int q = 0; q < nv; ++q) {
            const auto& row = ax[1].matrix[bv * nv + q];
            const auto [j0, j1] = ax[1].nonzero[bv * nv + q];
            for (int r = 0; r < nw; ++r) {
              glm::dvec3 s(0);
              for (int j = j0; j < j1; ++j)
                if (row[j] != 0) s += row[j] * tw[(size_t(i - ia) * J + (j - ja)) * nw + r];
              tv[(size_t(i - ia) * nv + q) * nw + r] = s;
            }
          }
        size_t base = ((size_t(bu) * F.boxes[1] + bv) * F.boxes[2] + bw) * F.coeffsPerBox();
        for (int pp = 0; pp < nu; ++pp) {
          const auto& row = ax[0].matrix[bu * nu + pp];
          const auto [i0, i1] = ax[0].nonzero[bu * nu + pp];
          for (int q = 0; q < nv; ++q)
            for (int r = 0; r < nw; ++r) {
              glm::dvec3 s(0);
              for (int i = i0; i < i1; ++i)
                if (row[i] != 0) s += row[i] * tv[(size_t(i - ia) * nv + q) * nw + r];
              F.coeffs[base + (size_t(pp) * nv + q) * nw + r] = s;
            }
        }
      }
  return F;
}

bool sameLatticeStructure(const Lattice& a, const Lattice& b) {
  return a.degree == b.degree && a.counts == b.counts && a.knots == b.knots && a.frameLinear == b.frameLinear &&
         a.frameOffset == b.frameOffset && a.outside == b.outside && a.controlPoints.size() == b.controlPoints.size();
}

}  // namespace sffd
