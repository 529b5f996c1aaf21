#include "analysis/buffer_compare.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace sffd {

CompareTolerance crossDeviceTolerance(std::string_view buffer, bool strict, bool f64) {
  CompareTolerance t;
  if (strict || buffer == "clip.headers") {
    t.bitExact = true;   // sub-triangle topology is the same everywhere, in fast mode too
    return t;
  }
  t.maxUlp = f64 ? 1e6 : 64;
  // 2e-6 between any two devices: one that fuses multiply-adds (NVIDIA's) and one that does not
  // (Mesa's, whose fast bits are the CPU's) differ as a GPU and the CPU do (an H200 against
  // lavapipe's dump: 1.04e-6 in one normal of the sphere).
  t.absOfScale = f64 ? 1e-12 : 2e-6;
  // The accurate control points solve A_n^{-1} S: the samples' rounding grows by up to |A_n^{-1}|_inf
  // (412 for n = 7), which the tessellated values do not see.
  if (buffer == "accurate.patches" && !f64) t.absOfScale = 1e-4;
  // The smooth patches fit 19 samples by least squares, which amplifies their rounding less, but beyond
  // 2e-6 with a driver that fuses multiply-adds: NVIDIA's (H200, driver 580) reached 2.2e-6 of the scale
  // in conformance and 3.9e-6 in the backend tests' cube.
  if (buffer == "deform.patches" && !f64) t.absOfScale = 1e-5;
  return t;
}
namespace {
// Maps the bits of a float onto a line where adjacent floats are adjacent integers.
int64_t ordered(float f) {
  int32_t i;
  std::memcpy(&i, &f, 4);
  return i < 0 ? int64_t(INT32_MIN) - i : i;
}
__int128 ordered(double d) {
  int64_t i;
  std::memcpy(&i, &d, 8);
  return i < 0 ? __int128(INT64_MIN) - i : __int128(i);
}
// Zeros and subnormals are one value: GL and Vulkan let a GPU flush subnormal results to zero (NVIDIA's
// do), so a value the CPU computes as 1e-38 may be 0 there, in strict mode too.
template <class T> bool bothBelowNormal(T a, T b) {
  return std::abs(a) < std::numeric_limits<T>::min() && std::abs(b) < std::numeric_limits<T>::min();
}
}  // namespace

uint64_t ulpDistance(float a, float b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : UINT64_MAX;
  int64_t d = ordered(a) - ordered(b);
  return uint64_t(d < 0 ? -d : d);
}

uint64_t ulpDistance(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : UINT64_MAX;
  __int128 d = ordered(a) - ordered(b);
  if (d < 0) d = -d;
  return d > __int128(UINT64_MAX) ? UINT64_MAX : uint64_t(d);
}

CompareResult compareBuffers(const std::vector<double>& a, const std::vector<double>& b, bool float32,
                             const CompareTolerance& tol) {
  CompareResult r;
  r.total = std::max(a.size(), b.size());
  if (a.size() != b.size()) {
    r.mismatched = r.total;
    r.maxAbs = INFINITY;
    r.maxUlp = UINT64_MAX;
    r.firstMismatch = std::min(a.size(), b.size());
    return r;
  }
  double scale = 0;
  for (size_t i = 0; i < a.size(); ++i) scale = std::max({scale, std::abs(a[i]), std::abs(b[i])});
  for (size_t i = 0; i < a.size(); ++i) {
    double x = a[i], y = b[i];
    uint64_t ulp;
    bool same;
    if (float32) {
      float fx = float(x), fy = float(y);
      ulp = ulpDistance(fx, fy);
      same = std::memcmp(&fx, &fy, 4) == 0 || bothBelowNormal(fx, fy);
    } else {
      ulp = ulpDistance(x, y);
      same = std::memcmp(&x, &y, 8) == 0 || bothBelowNormal(x, y);
    }
    double d = std::abs(x - y);
    if (std::isnan(d)) d = INFINITY;
    r.maxAbs = std::max(r.maxAbs, d);
    r.maxUlp = std::max(r.maxUlp, ulp);
    bool ok = tol.bitExact ? same : (same || double(ulp) <= tol.maxUlp || d <= tol.absOfScale * scale);
    if (!ok && !r.mismatched++) r.firstMismatch = i;
  }
  return r;
}

}  // namespace sffd
