#include "analysis/triangle_quality.h"

#include <algorithm>
#include <cmath>

namespace sffd {

double triangleQuality(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  double la = glm::length(b - c), lb = glm::length(c - a), lc = glm::length(a - b);
  double area = 0.5 * glm::length(glm::cross(b - a, c - a));
  double s = 0.5 * (la + lb + lc), longest = std::max({la, lb, lc});
  if (!(s > 0) || !(longest > 0)) return 0;
  double inradius = area / s;
  return std::min(1.0, 2 * std::sqrt(3.0) * inradius / longest);
}

double triangleMinAngleDeg(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  auto angle = [](glm::dvec3 u, glm::dvec3 v) {
    double nu = glm::length(u), nv = glm::length(v);
    if (!(nu > 0) || !(nv > 0)) return 0.0;
    return std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v)) * 180 / M_PI;
  };
  return std::min({angle(b - a, c - a), angle(a - b, c - b), angle(a - c, b - c)});
}

QualityStats qualityStats(const std::vector<std::array<glm::dvec3, 3>>& tris) {
  QualityStats S;
  S.count = tris.size();
  S.histogram.assign(20, 0);
  if (tris.empty()) return S;
  std::vector<double> q(tris.size()), area(tris.size());
  S.minAngleDeg = 180;
  double qsum = 0, asum = 0;
  for (size_t i = 0; i < tris.size(); ++i) {
    const auto& t = tris[i];
    q[i] = triangleQuality(t[0], t[1], t[2]);
    area[i] = 0.5 * glm::length(glm::cross(t[1] - t[0], t[2] - t[0]));
    S.minAngleDeg = std::min(S.minAngleDeg, triangleMinAngleDeg(t[0], t[1], t[2]));
    qsum += q[i];
    asum += area[i];
    S.histogram[std::min<size_t>(19, size_t(q[i] * 20))]++;
    if (q[i] < 0.3) S.shareBelow03 += 1;
  }
  S.shareBelow03 /= tris.size();
  std::vector<double> sorted = q;
  std::sort(sorted.begin(), sorted.end());
  auto pct = [&](const std::vector<double>& v, double p) { return v[std::min(v.size() - 1, size_t(p * (v.size() - 1) + 0.5))]; };
  S.quality[0] = sorted.front();
  S.quality[1] = pct(sorted, 0.01);
  S.quality[2] = pct(sorted, 0.5);
  S.quality[3] = qsum / tris.size();
  S.quality[4] = sorted.back();
  std::vector<double> aspect(q.size());
  for (size_t i = 0; i < q.size(); ++i) aspect[i] = q[i] > 0 ? 1 / q[i] : INFINITY;
  std::sort(aspect.begin(), aspect.end());
  S.aspect[0] = pct(aspect, 0.5);
  S.aspect[1] = pct(aspect, 0.9);
  S.aspect[2] = pct(aspect, 0.99);
  S.aspect[3] = aspect.back();
  double mean = asum / tris.size(), var = 0;
  S.areaRatio[0] = INFINITY;
  for (double a : area) {
    S.areaRatio[0] = std::min(S.areaRatio[0], a / mean);
    S.areaRatio[1] = std::max(S.areaRatio[1], a / mean);
    var += (a - mean) * (a - mean);
  }
  S.areaRatio[2] = std::sqrt(var / tris.size()) / mean;
  return S;
}

}  // namespace sffd
