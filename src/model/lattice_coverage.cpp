#include "model/lattice_coverage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sffd {

double shareOutsideLattice(const Mesh& mesh, const Lattice& L) {
  if (mesh.positions.empty()) return 0;
  size_t outside = 0;
  for (const glm::dvec3& x : mesh.positions) {
    const glm::dvec3 p = L.frameLinear * x + L.frameOffset;
    for (int a = 0; a < 3; ++a)
      if (!(p[a] >= L.domainLo(a) && p[a] <= L.domainHi(a))) {
        ++outside;
        break;
      }
  }
  return double(outside) / double(mesh.positions.size());
}

std::string outsideWarning(double share, const Lattice& L, const std::string& name) {
  if (!(share > 0.5)) return {};
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.0f%% of the mesh's vertices lie outside the box of lattice ", share * 100);
  return buf + name +
         (L.outside == OutsideMode::Keep ? ": they are left unmoved"
                                         : ": they follow the nearest knot box's polynomial (extrapolated), which grows fast away from the box");
}

std::string discontinuityWarning(const Lattice& L, const std::string& name) {
  static const char* axis = "uvw";
  for (int a = 0; a < 3; ++a) {
    const auto& k = L.knots[a];
    // Interior knots: strictly inside the domain.
    for (size_t i = size_t(L.degree[a]) + 1; i < size_t(L.counts[a]);) {
      size_t j = i;
      while (j < size_t(L.counts[a]) && k[j] == k[i]) ++j;
      const int multiplicity = int(j - i);
      if (multiplicity > L.degree[a] && k[i] > L.domainLo(a) && k[i] < L.domainHi(a)) {
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      ": the knot %g of axis %c is repeated %d times, more than the degree %d: the deformation jumps there "
                      "(the output tears along it)",
                      k[i], axis[a], multiplicity, L.degree[a]);
        return "lattice " + name + buf;
      }
      i = j;
    }
  }
  return {};
}

std::string resolutionWarning(const Mesh& mesh, const Lattice& L, bool doublePrecision, const std::string& name) {
  if (mesh.positions.empty()) return {};
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::dvec3& x : mesh.positions) lo = glm::min(lo, x), hi = glm::max(hi, x);
  const double size = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  // Per axis, the knot span holding the mesh's centre, in world units (the parameter map's inverse's column).
  const glm::dvec3 centre = L.frameLinear * (0.5 * (lo + hi)) + L.frameOffset;
  const glm::dmat3 toWorld = glm::inverse(L.frameLinear);
  double span = 0;
  for (int a = 0; a < 3; ++a) {
    const std::vector<double>& k = L.knots[a];
    const double u = std::clamp(centre[a], L.domainLo(a), L.domainHi(a));
    double width = L.domainHi(a) - L.domainLo(a);
    for (size_t i = size_t(L.degree[a]); i < size_t(L.counts[a]); ++i)
      if (k[i] <= u && u <= k[i + 1] && k[i + 1] > k[i]) width = k[i + 1] - k[i];
    span = std::max(span, width * glm::length(toWorld[a]));
  }
  const double resolution = std::ldexp(span, doublePrecision ? -53 : -24);
  if (!(size > 0) || !(resolution >= size / 128) || !std::isfinite(resolution)) return {};
  auto g = [](double v, const char* format) {
    char buf[32];
    std::snprintf(buf, sizeof buf, format, v);
    return std::string(buf);
  };
  const double share = resolution / size;
  return "the mesh is " + g(size, "%.3g") + " across, and the knot spans of lattice " + name + " that hold it " + g(span, "%.3g") +
         (doublePrecision ? ": double" : ": float") + " kernels resolve the result to about " + g(resolution, "%.2g") + ", " +
         (share < 1 ? g(100 * share, "%.2g") + "% of the mesh" : g(share, "%.2g") + " times its size") +
         (doublePrecision || std::ldexp(span, -53) >= size / 128 ? "; use a lattice closer to the mesh's size" : "; use --precision double");
}

}  // namespace sffd
