// Knot-box clipping (METHOD.md 2.1): Cui & Feng, "Smooth free-form deformation with sharp feature
// awareness" (2015), clipping step as in the authors' code (albuscrow/acaffd, `ACTriangle.py` /
// `model.py`: `ACPoly`, `OBJ.split`), itself the first step of the accurate FFD of Feng, Heng & Wong
// (1998) and Feng & Peng (2000): a triangle crossing knot planes is mapped by a piecewise polynomial,
// so it is cut into pieces that each lie in one knot box.
//
// Sutherland-Hodgman polygon splitting (Sutherland & Hodgman, "Reentrant polygon clipping", 1974) in
// lattice-parameter space, plane by plane, x then y then z. Every polygon vertex carries where it lies
// on the parent (a corner, a point on a parent edge, or an interior point) so that the output can be
// placed exactly on the parent surface later.
//
// Watertightness: a point on a parent edge is computed from that edge's endpoints, the one with the
// lower weldId first, never from the current (shorter) polygon edge. The two triangles of a shared edge
// then hold the same sequence of points on it, bit for bit, and classify them identically against
// every later plane, so they cut the edge at the same places.
#include "kernels/clip/knot_box_clip.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace sffd {

namespace {

struct PolyVertex {
  glm::dvec3 p;   // lattice-parameter position
  SubVertex v;
};
using Polygon = std::vector<PolyVertex>;

// The parent triangle in parameter space, and per edge its endpoint corners ordered by weldId.
struct Parent {
  std::array<glm::dvec3, 3> p;
  std::array<int, 3> lo, hi;
};

// Bit e set: the vertex lies on parent edge e (corners e and (e+1)%3).
unsigned edgeMask(const SubVertex& v) {
  switch (v.kind) {
    case SubVertexKind::Corner0: return 0b101u;   // edges 0 and 2
    case SubVertexKind::Corner1: return 0b011u;
    case SubVertexKind::Corner2: return 0b110u;
    case SubVertexKind::Edge0: return 0b001u;
    case SubVertexKind::Edge1: return 0b010u;
    case SubVertexKind::Edge2: return 0b100u;
    default: return 0u;
  }
}

bool lexLess(const glm::dvec3& a, const glm::dvec3& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

// The point where polygon edge (a, b) crosses the plane p_d = k (a and b strictly on opposite sides).
PolyVertex crossing(const Parent& T, const PolyVertex& a, const PolyVertex& b, int d, double k) {
  PolyVertex r;
  const unsigned common = edgeMask(a.v) & edgeMask(b.v);
  if (common) {
    // Both ends on parent edge e, so the polygon edge is a piece of it: measure from the parent edge's
    // lower-weldId endpoint, which is what the neighbour across e does too.
    const int e = std::countr_zero(common);
    const int lo = T.lo[e], hi = T.hi[e];
    double t = (k - T.p[lo][d]) / (T.p[hi][d] - T.p[lo][d]);
    t = std::clamp(t, 0.0, 1.0);   // only rounding can push it out
    r.v.kind = SubVertexKind(int(SubVertexKind::Edge0) + e);
    r.v.t = t;
    r.v.lam = glm::dvec3(0.0);
    r.v.lam[lo] = 1.0 - t;
    r.v.lam[hi] = t;
    r.p = T.p[lo] + t * (T.p[hi] - T.p[lo]);
  } else {
    // An interior chord, possibly shared by two pieces of this triangle that walk it in opposite
    // directions: interpolate from a fixed end so that both get the same point.
    const PolyVertex* s0 = &a;
    const PolyVertex* s1 = &b;
    if (lexLess(b.v.lam, a.v.lam)) std::swap(s0, s1);
    double s = (k - s0->p[d]) / (s1->p[d] - s0->p[d]);
    s = std::clamp(s, 0.0, 1.0);
    r.v.kind = SubVertexKind::Interior;
    r.v.t = 0;
    r.v.lam = s0->v.lam + s * (s1->v.lam - s0->v.lam);
    r.p = s0->p + s * (s1->p - s0->p);
  }
  // On the plane by construction: exactly, so that later classifications against it agree.
  r.p[d] = k;
  return r;
}

// Which side of p_d = k a polygon vertex is on; within `eps` of the plane counts as on it. Without the
// tolerance a point that lies on two planes at once (where a parent edge passes through a line of the
// lattice grid, common when mesh and lattice share a symmetry) reads as a hair off the second plane
// after rounding, and the second plane inserts a twin point next to it. The test depends only on the
// point, and points on a parent edge are the same bits in both of its triangles, so both decide alike.
int side(const PolyVertex& v, int d, double k, double eps) {
  const double x = v.p[d] - k;
  return x < -eps ? -1 : (x > eps ? 1 : 0);
}

// Splits a convex polygon by p_d = k. Vertices on the plane go to both pieces (never duplicated
// within one), crossings are inserted into both. Returns false, building nothing, when no vertex lies
// strictly on one of the two sides: a plane that only touches the polygon makes no piece.
bool splitPolygon(const Parent& T, const Polygon& poly, int d, double k, double eps, Polygon& below, Polygon& above,
                  bool& wholeBelow, std::vector<int>& sides) {
  const size_t n = poly.size();
  sides.resize(n);
  bool neg = false, pos = false;
  for (size_t i = 0; i < n; ++i) {
    sides[i] = side(poly[i], d, k, eps);
    neg |= sides[i] < 0;
    pos |= sides[i] > 0;
  }
  wholeBelow = !pos;
  if (!neg || !pos) return false;
  below.clear();
  above.clear();
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    if (sides[i] <= 0) below.push_back(poly[i]);
    if (sides[i] >= 0) above.push_back(poly[i]);
    if (sides[i] * sides[j] < 0) {
      PolyVertex x = crossing(T, poly[i], poly[j], d, k);
      below.push_back(x);
      above.push_back(x);
    }
  }
  return true;
}

// Relative distance from a plane below which a vertex counts as on it (see `side`).
constexpr double kOnPlane = 1e-13;
// A fan triangle is degenerate (zero area up to rounding) when |sin| of its angle at the apex is below
// kCollinear (a parent of no area), or when two of its corners are closer than kCoincident times the
// parent's diameter (twin points that rounding may still make, a few ulps apart).
constexpr double kCollinear = 1e-14;
constexpr double kCoincident = 1e-13;

}  // namespace

std::vector<SubTriangle> clipAgainstKnotBoxes(const Mesh& mesh, const Lattice& lattice) {
  std::vector<SubTriangle> out;
  out.reserve(mesh.triangles.size() * 2);
  clipAgainstKnotBoxes(mesh, lattice, 0, mesh.triangles.size(), out);
  return out;
}

void clipAgainstKnotBoxes(const Mesh& mesh, const Lattice& lattice, size_t firstTriangle, size_t endTriangle,
                          std::vector<SubTriangle>& out) {
  // Interior knots: the distinct values strictly inside the domain, ascending.
  std::array<std::vector<double>, 3> planes;
  for (int a = 0; a < 3; ++a) {
    const double lo = lattice.domainLo(a), hi = lattice.domainHi(a);
    for (double k : lattice.knots[a])
      if (k > lo && k < hi && (planes[a].empty() || planes[a].back() != k)) planes[a].push_back(k);
  }

  std::vector<Polygon> current, next;
  Polygon below, above, rest;
  std::vector<int> sides;

  for (size_t t = firstTriangle; t < endTriangle; ++t) {
    const auto& tri = mesh.triangles[t];
    Parent T;
    for (int c = 0; c < 3; ++c) T.p[c] = lattice.frameLinear * mesh.positions[tri[c]] + lattice.frameOffset;
    glm::dvec3 scale(0.0);
    double diameter = 0;
    for (int c = 0; c < 3; ++c) {
      scale = glm::max(scale, glm::abs(T.p[c]));
      diameter = std::max(diameter, glm::length(T.p[(c + 1) % 3] - T.p[c]));
    }
    // On-plane tolerance per axis: a few hundred ulps of the parent's coordinates in parameter space.
    const glm::dvec3 eps = kOnPlane * (scale + glm::dvec3(diameter));
    for (int e = 0; e < 3; ++e) {
      const int a = e, b = (e + 1) % 3;
      const bool aFirst = mesh.weldId[tri[a]] <= mesh.weldId[tri[b]];
      T.lo[e] = aFirst ? a : b;
      T.hi[e] = aFirst ? b : a;
    }

    current.assign(1, Polygon(3));
    for (int c = 0; c < 3; ++c) {
      PolyVertex& pv = current[0][c];
      pv.p = T.p[c];
      pv.v.kind = SubVertexKind(int(SubVertexKind::Corner0) + c);
      pv.v.t = 0;
      pv.v.lam = glm::dvec3(0.0);
      pv.v.lam[c] = 1.0;
    }

    for (int d = 0; d < 3; ++d) {
      if (planes[d].empty()) continue;
      next.clear();
      for (Polygon& poly : current) {
        double mn = poly[0].p[d], mx = mn;
        for (const PolyVertex& pv : poly) {
          mn = std::min(mn, pv.p[d]);
          mx = std::max(mx, pv.p[d]);
        }
        // Candidate planes: beyond these every vertex is strictly on one side.
        auto first = std::lower_bound(planes[d].begin(), planes[d].end(), mn - 2 * eps[d]);
        auto last = std::upper_bound(planes[d].begin(), planes[d].end(), mx + 2 * eps[d]);
        rest = std::move(poly);
        // Ascending sweep: the piece below a plane lies below every later one, so only the piece
        // above goes on.
        for (auto it = first; it < last; ++it) {
          bool wholeBelow = false;
          if (!splitPolygon(T, rest, d, *it, eps[d], below, above, wholeBelow, sides)) {
            if (wholeBelow) break;
            continue;
          }
          if (below.size() >= 3) next.push_back(below);
          std::swap(rest, above);
        }
        if (rest.size() >= 3) next.push_back(std::move(rest));
      }
      std::swap(current, next);
    }

    // Fan each convex piece from its first vertex; the pieces keep the parent's vertex order, so the
    // sub-triangles keep its winding.
    for (const Polygon& poly : current)
      for (size_t i = 1; i + 1 < poly.size(); ++i) {
        const glm::dvec3 a = poly[i].p - poly[0].p, b = poly[i + 1].p - poly[0].p;
        const double la = glm::length(a), lb = glm::length(b), lc = glm::length(b - a);
        if (!(std::min({la, lb, lc}) > kCoincident * diameter)) continue;
        if (!(glm::length(glm::cross(a, b)) > kCollinear * la * lb)) continue;
        SubTriangle s;
        s.parent = uint32_t(t);
        s.corners = {poly[0].v, poly[i].v, poly[i + 1].v};
        out.push_back(s);
      }
  }
}

}  // namespace sffd
