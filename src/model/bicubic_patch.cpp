#include "model/bicubic_patch.h"

#include <algorithm>
#include <cmath>

namespace sffd {
namespace {

void bernstein3(double t, double b[4], double d[4]) {
  double s = 1.0 - t;
  b[0] = s * s * s;
  b[1] = 3.0 * t * s * s;
  b[2] = 3.0 * t * t * s;
  b[3] = t * t * t;
  d[0] = -3.0 * s * s;
  d[1] = 3.0 * s * s - 6.0 * t * s;
  d[2] = 6.0 * t * s - 3.0 * t * t;
  d[3] = 3.0 * t * t;
}

}  // namespace

void evaluateBicubic(const BicubicPatch& P, double u, double v, glm::dvec3& S, glm::dvec3& Su, glm::dvec3& Sv) {
  double bu[4], du[4], bv[4], dv[4];
  bernstein3(u, bu, du);
  bernstein3(v, bv, dv);
  S = Su = Sv = glm::dvec3(0.0);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      const glm::dvec3& q = P.points[4 * r + c];
      S += (bu[r] * bv[c]) * q;
      Su += (du[r] * bv[c]) * q;
      Sv += (bu[r] * dv[c]) * q;
    }
}

glm::dvec3 bicubicNormal(const BicubicPatch& P, double u, double v) {
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const auto& q : P.points) lo = glm::min(lo, q), hi = glm::max(hi, q);
  glm::dvec3 ext = hi - lo;
  double scale = std::max({ext.x, ext.y, ext.z, 1e-300});
  double scale2 = scale * scale;
  glm::dvec3 S, Su, Sv;
  evaluateBicubic(P, u, v, S, Su, Sv);
  glm::dvec3 n = glm::cross(Su, Sv);
  double len = glm::length(n);
  if (len > 1e-10 * scale2) return n / len;
  for (double delta : {1e-6, 1e-4, 1e-2}) {
    double uu = u + (u < 0.5 ? delta : u > 0.5 ? -delta : 0.0);
    double vv = v + (v < 0.5 ? delta : v > 0.5 ? -delta : 0.0);
    evaluateBicubic(P, uu, vv, S, Su, Sv);
    n = glm::cross(Su, Sv);
    len = glm::length(n);
    if (len > 1e-14 * scale2) return n / len;
  }
  return glm::dvec3(0, 0, 1);
}

}  // namespace sffd
