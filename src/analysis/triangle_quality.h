// Shape statistics of a set of triangles: what `sffd clip --stats` reports and docs/ACCURACY.md
// compares between regular and knot-box clipping.
#pragma once
#include <array>
#include <vector>

#include <glm/glm.hpp>

namespace sffd {

// quality = 2*sqrt(3)*inradius / longest edge (1 for equilateral, 0 for degenerate); aspect = 1/quality.
double triangleQuality(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);
double triangleMinAngleDeg(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

struct QualityStats {
  size_t count = 0;
  double minAngleDeg = 0, quality[5] = {};   // quality: min, 1st percentile, median, mean, max
  double shareBelow03 = 0;                   // share of triangles with quality < 0.3
  double aspect[4] = {};                     // aspect ratio: median, 90th, 99th percentile, max
  double areaRatio[3] = {};                  // area / mean area: min, max, coefficient of variation
  std::vector<size_t> histogram;             // quality in 20 bins of width 0.05
};

QualityStats qualityStats(const std::vector<std::array<glm::dvec3, 3>>& triangles);

}  // namespace sffd
