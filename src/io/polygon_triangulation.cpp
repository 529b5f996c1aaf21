// Polygons of mesh files into triangles. A convex polygon is fanned from its first corner (what every
// reader did before, so convex files read exactly as they did); a concave one is cut by ear clipping
// (Meisters, "Polygons have ears", 1975) in the plane of its Newell normal, which keeps every triangle
// turning the polygon's way: a fan across a concave polygon's notch would flip triangles and overlap.
// A polygon without area (all corners on a line, or repeated corners only) is dropped and counted.
#include <algorithm>
#include <cmath>

#include "io/mesh_io_internal.h"

namespace sffd::meshio {
namespace {

double cross2(const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Whether p lies inside or on the triangle (a, b, c), counter-clockwise.
bool inTriangle(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return cross2(a, b, p) >= 0 && cross2(b, c, p) >= 0 && cross2(c, a, p) >= 0;
}

}  // namespace

void addPolygon(Mesh& mesh, const uint32_t* corners, size_t n, size_t& dropped) {
  if (n == 3) {
    mesh.triangles.push_back({corners[0], corners[1], corners[2]});
    return;
  }
  // Corners not read yet (a file whose faces come before its vertices): the fan, as before.
  for (size_t i = 0; i < n; ++i)
    if (corners[i] >= mesh.positions.size()) {
      fanTriangulate(corners, n, mesh.triangles);
      return;
    }
  // Consecutive repeats of a corner add nothing.
  std::vector<uint32_t> poly;
  for (size_t i = 0; i < n; ++i)
    if (poly.empty() || corners[i] != poly.back()) poly.push_back(corners[i]);
  while (poly.size() > 1 && poly.front() == poly.back()) poly.pop_back();
  const auto& P = mesh.positions;
  glm::dvec3 normal(0.0), lo = P[poly[0]], hi = lo;   // Newell's normal: twice the vector area
  for (size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 &a = P[poly[i]], &b = P[poly[(i + 1) % poly.size()]];
    normal += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    lo = glm::min(lo, a), hi = glm::max(hi, a);
  }
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  if (poly.size() < 3 || !(glm::length(normal) > 1e-12 * extent * extent)) {
    ++dropped;
    return;
  }
  // The plane's two other axes, ordered so that the polygon runs counter-clockwise in them.
  int k = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(normal[a]) > std::abs(normal[k])) k = a;
  int u = (k + 1) % 3, v = (k + 2) % 3;
  if (normal[k] < 0) std::swap(u, v);
  std::vector<glm::dvec2> q(poly.size());
  for (size_t i = 0; i < poly.size(); ++i) q[i] = {P[poly[i]][u], P[poly[i]][v]};
  bool convex = true;
  for (size_t i = 0; i < q.size() && convex; ++i)
    convex = cross2(q[i], q[(i + 1) % q.size()], q[(i + 2) % q.size()]) >= 0;
  if (convex) {
    fanTriangulate(poly.data(), poly.size(), mesh.triangles);
    return;
  }
  std::vector<size_t> left(q.size());
  for (size_t i = 0; i < left.size(); ++i) left[i] = i;
  while (left.size() > 3) {
    const size_t m = left.size();
    size_t ear = m;
    for (size_t i = 0; i < m && ear == m; ++i) {
      const size_t a = left[(i + m - 1) % m], b = left[i], c = left[(i + 1) % m];
      if (cross2(q[a], q[b], q[c]) <= 0) continue;   // reflex or flat: not an ear
      bool empty = true;
      for (size_t j = 0; j < m && empty; ++j) {
        const size_t p = left[j];
        if (p == a || p == b || p == c || q[p] == q[a] || q[p] == q[b] || q[p] == q[c]) continue;
        empty = !inTriangle(q[p], q[a], q[b], q[c]);
      }
      if (empty) ear = i;
    }
    if (ear == m) {   // self-intersecting or numerically flat: the rest as a fan
      std::vector<uint32_t> rest;
      for (size_t i : left) rest.push_back(poly[i]);
      fanTriangulate(rest.data(), rest.size(), mesh.triangles);
      return;
    }
    mesh.triangles.push_back({poly[left[(ear + m - 1) % m]], poly[left[ear]], poly[left[(ear + 1) % m]]});
    left.erase(left.begin() + std::ptrdiff_t(ear));
  }
  mesh.triangles.push_back({poly[left[0]], poly[left[1]], poly[left[2]]});
}

void noteDroppedPolygons(Mesh& mesh, size_t dropped) {
  if (dropped)
    mesh.warnings.push_back(std::to_string(dropped) + (dropped == 1 ? " polygon" : " polygons") +
                            " without area dropped (all corners on a line or repeated)");
}

}  // namespace sffd::meshio
