#include "model/lattice_coverage.h"

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

}  // namespace sffd
