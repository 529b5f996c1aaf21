// Build-time tool: generates the crack-free split-pattern table (METHOD.md 4.2, offline
// generator steps 1-6) as a C++ source compiled into sffd_core (kernels/clip/split_pattern_table.h).
// usage: split_pattern_gen [--nmax N] [--verbose] OUT.cpp
//
// For every sorted count triple a <= b <= c <= a + b, c <= N: boundary points at t/n on the edges
// of the canonical triangle, interior seeds on a unit triangular lattice kept 0.5 from the
// boundary, Delaunay, 5 Lloyd iterations (boundary fixed), re-triangulated after each.
//
// Robustness: points live in affine coordinates (u, v) = (lambda1, lambda2) on a 2^-30 fixed-point
// grid. Boundary points come from splitEdgeLambda, whose pair sums to exactly 1, so each edge's
// points are exactly collinear (v = 0, u + v = 1, u = 0) and orientation tests are exact in int64.
// Triangulation is incremental (point location, 1->3 or edge split, Lawson flips) inside the
// canonical triangle itself: no super triangle, boundary edges are never flipped, a flip is taken
// only when the new triangles are strictly positive, so the result is always a valid
// triangulation of the triangle. Only the incircle test is in double (the Euclidean metric), which
// at worst picks another diagonal among nearly cocircular points. Output is checked exactly.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "kernels/clip/split_pattern_table.h"

namespace fs = std::filesystem;
using namespace sffd;

namespace {

constexpr int64_t kScale = int64_t(1) << 30;  // fixed-point unit of u and v
constexpr int kLloydIterations = 5;

struct Fixed {
  int64_t u, v;
};
struct Vec2 {
  double x, y;
};

// Exact: |differences| <= 2^30, so products fit in 2^60 and their difference in int64.
int orient(const Fixed& a, const Fixed& b, const Fixed& c) {
  int64_t d = (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
  return (d > 0) - (d < 0);
}

// > 0 when d is inside the circumcircle of the CCW triangle abc (Euclidean frame).
double incircle(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  double adx = a.x - d.x, ady = a.y - d.y, bdx = b.x - d.x, bdy = b.y - d.y, cdx = c.x - d.x, cdy = c.y - d.y;
  return (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy) + (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy) +
         (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady);
}

// Triangle: CCW vertices; nb[i] is the triangle across edge (v[i], v[i+1]), -1 on the boundary.
struct Tri {
  int v[3];
  int nb[3];
};

// Delaunay triangulation of points p (fixed point; x: the same in the Euclidean frame) inside the
// triangle of points c0, c1, c2. Points are inserted one at a time, each new and inside or on it.
class Triangulation {
 public:
  Triangulation(const std::vector<Fixed>& p, const std::vector<Vec2>& x, int c0, int c1, int c2) : p_(p), x_(x) {
    tris_.reserve(2 * p.size());
    tris_.push_back({{c0, c1, c2}, {-1, -1, -1}});
  }

  void insert(int q) {
    int t = locate(q);
    int zeros = 0, onEdge = -1;
    for (int i = 0; i < 3; ++i)
      if (orient(p_[tris_[t].v[i]], p_[tris_[t].v[(i + 1) % 3]], p_[q]) == 0) ++zeros, onEdge = i;
    if (zeros > 1) throw std::runtime_error("duplicate point");
    std::vector<int>& stack = stack_;
    if (zeros == 0) splitInside(t, q, stack);
    else splitEdge(t, onEdge, q, stack);
    // Lawson: every triangle on the stack has q at v[2]; test the edge opposite it.
    while (!stack.empty()) {
      int ti = stack.back();
      stack.pop_back();
      flipIfNeeded(ti, stack);
    }
    last_ = t;
  }

  const std::vector<Tri>& triangles() const { return tris_; }

 private:
  // Visibility walk from the last insertion (exact orientation), brute force if it wanders.
  int locate(int q) {
    int t = last_, from = -1;
    for (size_t steps = 0; steps < 4 * tris_.size() + 16; ++steps) {
      int next = -1;
      for (int i = 0; i < 3 && next < 0; ++i) {
        const Tri& tr = tris_[t];
        if (tr.nb[i] == from && from >= 0) continue;
        if (orient(p_[tr.v[i]], p_[tr.v[(i + 1) % 3]], p_[q]) < 0) {
          if (tr.nb[i] < 0) throw std::runtime_error("point outside the triangle");
          next = tr.nb[i];
        }
      }
      if (next < 0) return t;
      from = t;
      t = next;
    }
    for (size_t i = 0; i < tris_.size(); ++i) {
      const Tri& tr = tris_[i];
      if (orient(p_[tr.v[0]], p_[tr.v[1]], p_[q]) >= 0 && orient(p_[tr.v[1]], p_[tr.v[2]], p_[q]) >= 0 &&
          orient(p_[tr.v[2]], p_[tr.v[0]], p_[q]) >= 0)
        return int(i);
    }
    throw std::runtime_error("point not located");
  }

  // Sets tris_[t] = (a, b, c) with its outer neighbours, and points those neighbours back at t.
  void set(int t, int a, int b, int c, int nab, int nbc, int nca) {
    tris_[t] = {{a, b, c}, {nab, nbc, nca}};
    for (int i = 0; i < 3; ++i) {
      int o = tris_[t].nb[i];
      if (o < 0) continue;
      int s = tris_[t].v[i], e = tris_[t].v[(i + 1) % 3];
      for (int j = 0; j < 3; ++j)
        if (tris_[o].v[j] == e && tris_[o].v[(j + 1) % 3] == s) tris_[o].nb[j] = t;
    }
  }
  int add() {
    tris_.push_back({});
    return int(tris_.size()) - 1;
  }

  void splitInside(int t, int q, std::vector<int>& stack) {
    Tri o = tris_[t];
    int t1 = t, t2 = add(), t3 = add();
    set(t1, o.v[0], o.v[1], q, o.nb[0], t2, t3);
    set(t2, o.v[1], o.v[2], q, o.nb[1], t3, t1);
    set(t3, o.v[2], o.v[0], q, o.nb[2], t1, t2);
    stack.insert(stack.end(), {t1, t2, t3});
  }

  // q lies strictly inside edge i of t; splits t and the triangle across (if any) in two.
  void splitEdge(int t, int i, int q, std::vector<int>& stack) {
    Tri o = tris_[t];
    int a = o.v[i], b = o.v[(i + 1) % 3], c = o.v[(i + 2) % 3];
    int nbc = o.nb[(i + 1) % 3], nca = o.nb[(i + 2) % 3], u = o.nb[i];
    int t1 = t, t2 = add();
    if (u < 0) {
      set(t1, b, c, q, nbc, t2, -1);
      set(t2, c, a, q, nca, -1, t1);
      stack.insert(stack.end(), {t1, t2});
      return;
    }
    Tri w = tris_[u];
    int j = 0;
    while (w.v[j] != b) ++j;  // w = (b, a, d) from j
    int d = w.v[(j + 2) % 3], nad = w.nb[(j + 1) % 3], ndb = w.nb[(j + 2) % 3];
    int u1 = u, u2 = add();
    set(t1, b, c, q, nbc, t2, -1);
    set(t2, c, a, q, nca, -1, t1);
    set(u1, d, b, q, ndb, -1, u2);
    set(u2, a, d, q, nad, u1, -1);
    // the four inner edges, linked now that all four exist
    tris_[t1].nb[2] = u1, tris_[u1].nb[1] = t1;
    tris_[t2].nb[1] = u2, tris_[u2].nb[2] = t2;
    stack.insert(stack.end(), {t1, t2, u1, u2});
  }

  void flipIfNeeded(int t, std::vector<int>& stack) {
    Tri o = tris_[t];
    int a = o.v[0], b = o.v[1], q = o.v[2], u = o.nb[0];
    if (u < 0) return;  // a boundary edge stays
    Tri w = tris_[u];
    int j = 0;
    while (w.v[j] != b) ++j;  // w = (b, a, d) from j
    int d = w.v[(j + 2) % 3];
    if (incircle(x_[a], x_[b], x_[q], x_[d]) <= 0) return;
    if (orient(p_[a], p_[d], p_[q]) <= 0 || orient(p_[d], p_[b], p_[q]) <= 0) return;  // not strictly convex
    int nad = w.nb[(j + 1) % 3], ndb = w.nb[(j + 2) % 3];
    set(t, a, d, q, nad, u, o.nb[2]);
    set(u, d, b, q, ndb, o.nb[1], t);
    stack.insert(stack.end(), {t, u});
  }

  const std::vector<Fixed>& p_;
  const std::vector<Vec2>& x_;
  std::vector<Tri> tris_;
  std::vector<int> stack_;
  int last_ = 0;
};

struct Pattern {
  int a, b, c;
  std::vector<Fixed> p;       // boundary first (edge 0, 1, 2 by step), then interior
  std::vector<int> tris;      // 3 per triangle, CCW
};

// A triangle clipped by two half-planes has at most 5 corners.
struct Poly {
  Vec2 p[8];
  int n = 0;
};

// The part of polygon `poly` closer to s than to o (bisector clip).
Poly clipCloser(const Poly& poly, Vec2 s, Vec2 o) {
  Vec2 m{(s.x + o.x) / 2, (s.y + o.y) / 2}, n{o.x - s.x, o.y - s.y};
  auto f = [&](Vec2 p) { return (p.x - m.x) * n.x + (p.y - m.y) * n.y; };
  Poly out;
  for (int i = 0; i < poly.n; ++i) {
    Vec2 p = poly.p[i], q = poly.p[(i + 1) % poly.n];
    double fp = f(p), fq = f(q);
    if (fp <= 0) out.p[out.n++] = p;
    if ((fp < 0 && fq > 0) || (fq < 0 && fp > 0)) {
      double s2 = fp / (fp - fq);
      out.p[out.n++] = {p.x + s2 * (q.x - p.x), p.y + s2 * (q.y - p.y)};
    }
  }
  return out;
}

Pattern generate(int a, int b, int c) {
  auto C = splitCanonicalTriangle(a, b, c);
  Vec2 e1{C[1][0], C[1][1]}, e2{C[2][0], C[2][1]};  // C0 is the origin
  auto toEuclid = [&](const Fixed& f) {
    double u = double(f.u) / kScale, v = double(f.v) / kScale;
    return Vec2{u * e1.x + v * e2.x, u * e1.y + v * e2.y};
  };
  auto toFixed = [&](Vec2 x) {
    double v = x.y / e2.y, u = (x.x - v * e2.x) / e1.x;
    return Fixed{std::llround(u * kScale), std::llround(v * kScale)};
  };

  Pattern pat{a, b, c, {}, {}};
  // Boundary, exact: edge e runs from corner e to corner e+1; (u, v) = (lambda1, lambda2).
  const int n[3] = {a, b, c};
  for (int e = 0; e < 3; ++e)
    for (int t = 0; t < n[e]; ++t) {
      auto l = splitEdgeLambda(t, n[e]);
      int64_t s = std::llround(double(l[0]) * kScale), f = std::llround(double(l[1]) * kScale);
      pat.p.push_back(e == 0 ? Fixed{f, 0} : e == 1 ? Fixed{s, f} : Fixed{0, s});
    }
  const int nb = int(pat.p.size());

  // Interior seeds: rows parallel to C0C1 at spacing sqrt(3)/2, odd rows shifted by 1/2.
  const double h = std::sqrt(3.0) / 2;
  const double len[3] = {std::hypot(e1.x, e1.y), std::hypot(e2.x - e1.x, e2.y - e1.y), std::hypot(e2.x, e2.y)};
  Vec2 corner[3] = {{0, 0}, e1, e2};
  for (int r = 1; r * h < e2.y; ++r)
    for (int k = -1; k <= a + c + 1; ++k) {
      Vec2 x{k + (r % 2) * 0.5, r * h};
      bool keep = true;
      for (int e = 0; e < 3 && keep; ++e) {
        Vec2 s = corner[e], f = corner[(e + 1) % 3];
        keep = ((f.x - s.x) * (x.y - s.y) - (f.y - s.y) * (x.x - s.x)) / len[e] >= 0.5;
      }
      if (keep) pat.p.push_back(toFixed(x));
    }

  std::vector<Tri> tris;
  for (int it = 0;; ++it) {
    std::vector<Vec2> x(pat.p.size());
    for (size_t i = 0; i < x.size(); ++i) x[i] = toEuclid(pat.p[i]);
    Triangulation tr(pat.p, x, 0, a, a + b);
    for (int i = 0; i < int(pat.p.size()); ++i)
      if (i != 0 && i != a && i != a + b) tr.insert(i);
    tris = tr.triangles();
    if (it == kLloydIterations) break;

    // Lloyd: each interior vertex moves to the centroid of its Voronoi cell within its star.
    std::vector<Vec2> sum(pat.p.size(), {0, 0});
    std::vector<double> area(pat.p.size(), 0);
    for (const Tri& t : tris)
      for (int k = 0; k < 3; ++k) {
        int s = t.v[k];
        if (s < nb) continue;
        Poly poly{{x[t.v[0]], x[t.v[1]], x[t.v[2]]}, 3};
        poly = clipCloser(clipCloser(poly, x[s], x[t.v[(k + 1) % 3]]), x[s], x[t.v[(k + 2) % 3]]);
        double A = 0, cx = 0, cy = 0;
        for (int i = 0; i < poly.n; ++i) {
          Vec2 p = poly.p[i], q = poly.p[(i + 1) % poly.n];
          double w = p.x * q.y - q.x * p.y;
          A += w, cx += (p.x + q.x) * w, cy += (p.y + q.y) * w;
        }
        if (poly.n < 3 || A <= 0) continue;
        area[s] += A / 2, sum[s].x += cx / 6, sum[s].y += cy / 6;  // = area * centroid
      }
    for (int i = nb; i < int(pat.p.size()); ++i) {
      if (area[i] <= 0) continue;
      Fixed f = toFixed({sum[i].x / area[i], sum[i].y / area[i]});
      // The centroid is inside the star; a move onto the boundary would break the t/n edges.
      if (f.u > 0 && f.v > 0 && f.u + f.v < kScale) pat.p[i] = f;
    }
  }

  // Exact check: positive triangles tiling the domain (areas sum to it, its edges are the only
  // boundary edges), so a valid triangulation of the canonical triangle.
  __int128 total = 0;
  int boundaryEdges = 0;
  for (const Tri& t : tris) {
    const Fixed &p0 = pat.p[t.v[0]], &p1 = pat.p[t.v[1]], &p2 = pat.p[t.v[2]];
    int64_t d = (p1.u - p0.u) * (p2.v - p0.v) - (p1.v - p0.v) * (p2.u - p0.u);
    if (d <= 0) throw std::runtime_error("non-positive triangle");
    total += d;
    for (int k = 0; k < 3; ++k) {
      if (t.nb[k] >= 0) continue;
      ++boundaryEdges;
      int s = t.v[k], e = t.v[(k + 1) % 3];
      if (!(s < nb && (e == (s + 1) % nb))) throw std::runtime_error("boundary edge off the boundary");
    }
  }
  if (total != __int128(kScale) * kScale || boundaryEdges != nb)
    throw std::runtime_error("triangles do not tile the canonical triangle");

  // Canonical order: each triangle rotated to start at its smallest index, then sorted.
  std::vector<std::array<int, 3>> sorted;
  for (const Tri& t : tris) {
    int k = int(std::min_element(t.v, t.v + 3) - t.v);
    sorted.push_back({t.v[k], t.v[(k + 1) % 3], t.v[(k + 2) % 3]});
  }
  std::sort(sorted.begin(), sorted.end());
  for (auto& t : sorted) pat.tris.insert(pat.tris.end(), t.begin(), t.end());
  return pat;
}

// Exact, locale-independent hexadecimal float literal.
std::string hexFloat(float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, 4);
  if (bits == 0) return "0.f";
  int exp = int(bits >> 23) - 127;
  if (bits >> 31 || exp == -127 || exp == 128) throw std::runtime_error("unexpected float");
  uint32_t mant = (bits & 0x7fffff) << 1;  // 24 bits = 6 hex digits
  char buf[32];
  int len = std::snprintf(buf, sizeof buf, "0x1.%06x", mant);
  while (buf[len - 1] == '0') --len;
  if (buf[len - 1] == '.') --len;
  return std::string(buf, len) + "p" + std::to_string(exp) + "f";
}

std::string readText(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace

int main(int argc, char** argv) {
  int nmax = 24;
  bool verbose = false;
  fs::path outPath;
  bool bad = false;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--nmax" && i + 1 < argc) nmax = std::atoi(argv[++i]);
    else if (arg == "--verbose") verbose = true;
    else if (outPath.empty() && arg[0] != '-') outPath = arg;
    else bad = true;
  }
  if (bad || outPath.empty() || nmax < 1 || nmax > 200) {
    std::cerr << "usage: split_pattern_gen [--nmax N] [--verbose] OUT.cpp\n";
    return 2;
  }
  try {
    auto start = std::chrono::steady_clock::now();
    std::vector<SplitPattern> entries(size_t(nmax) * nmax * nmax, SplitPattern{0, 0, 0, 0});
    std::vector<SplitPatternVertex> verts;
    std::vector<int> tris;
    for (int a = 1; a <= nmax; ++a)
      for (int b = a; b <= nmax; ++b)
        for (int c = b; c <= std::min(nmax, a + b); ++c) {
          Pattern p = generate(a, b, c);
          if (p.p.size() > 65535) throw std::runtime_error("pattern too large for 16-bit indices");
          entries[splitPatternKey(nmax, a, b, c)] = {uint32_t(verts.size()), uint32_t(p.p.size()),
                                                     uint32_t(tris.size() / 3), uint32_t(p.tris.size() / 3)};
          const int n[3] = {a, b, c};
          int i = 0;
          for (int e = 0; e < 3; ++e)
            for (int t = 0; t < n[e]; ++t, ++i) {
              // Stored analytically; the fixed-point position is the same pair by construction.
              auto l = splitEdgeLambda(t, n[e]);
              SplitPatternVertex v{{0, 0, 0}, uint8_t(e), 0, uint16_t(t)};
              v.lambda[e] = l[0], v.lambda[(e + 1) % 3] = l[1];
              verts.push_back(v);
            }
          for (; i < int(p.p.size()); ++i) {
            const Fixed& f = p.p[i];
            verts.push_back({{float(double(kScale - f.u - f.v) / kScale), float(double(f.u) / kScale),
                              float(double(f.v) / kScale)},
                             kSplitEdgeInterior, 0, 0});
          }
          tris.insert(tris.end(), p.tris.begin(), p.tris.end());
        }
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    std::string o;
    o.reserve(verts.size() * 48 + tris.size() * 5 + entries.size() * 8);
    o += "// Generated by tools/split_pattern_gen.cpp at build time (Nmax " + std::to_string(nmax) +
         "). Do not edit.\n#include \"kernels/clip/split_pattern_table.h\"\nnamespace sffd {\nnamespace {\n";
    o += "const SplitPattern kPatterns[] = {\n";
    for (size_t i = 0; i < entries.size(); ++i) {
      const SplitPattern& e = entries[i];
      o += e.vertexCount == 0 ? "{}," : "{" + std::to_string(e.firstVertex) + "," + std::to_string(e.vertexCount) + "," +
                                            std::to_string(e.firstTriangle) + "," + std::to_string(e.triangleCount) + "},";
      if (i % nmax == size_t(nmax) - 1) o += "\n";
    }
    o += "};\nconst SplitPatternVertex kVertices[] = {\n";
    for (const SplitPatternVertex& v : verts)
      o += "{{" + hexFloat(v.lambda[0]) + "," + hexFloat(v.lambda[1]) + "," + hexFloat(v.lambda[2]) + "}," +
           std::to_string(v.edge) + ",0," + std::to_string(v.step) + "},\n";
    o += "};\nconst uint16_t kTriangles[] = {\n";
    for (size_t i = 0; i < tris.size(); ++i) o += std::to_string(tris[i]) + (i % 24 == 23 ? ",\n" : ",");
    o += "\n};\n}  // namespace\n"
         "extern constinit const SplitPatternTable kGeneratedSplitPatternTable;\n"
         "constinit const SplitPatternTable kGeneratedSplitPatternTable(" +
         std::to_string(nmax) + ", kPatterns, kVertices, kTriangles);\n}  // namespace sffd\n";

    // Only rewrite when changed, so the library is not recompiled needlessly.
    if (!(fs::exists(outPath) && readText(outPath) == o)) {
      fs::path tmp = outPath;
      tmp += ".tmp";
      std::ofstream f(tmp, std::ios::binary);
      if (!(f << o) || (f.close(), !f)) throw std::runtime_error("cannot write " + tmp.string());
      fs::rename(tmp, outPath);
    }
    if (verbose)
      std::printf("split patterns: Nmax %d, %zu patterns, %zu vertices, %zu triangles, %zu bytes of data, %.3f s\n",
                  nmax, size_t(std::count_if(entries.begin(), entries.end(), [](auto& e) { return e.vertexCount; })),
                  verts.size(), tris.size() / 3,
                  entries.size() * sizeof(SplitPattern) + verts.size() * sizeof(SplitPatternVertex) + tris.size() * 2,
                  seconds);
  } catch (const std::exception& e) {
    std::cerr << "split_pattern_gen: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
