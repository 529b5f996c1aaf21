// Comparison of two output buffers of the same job from two backends (sffd conform and the
// conformance tests): largest absolute difference, largest distance in units in the last place,
// and how many elements lie outside the tolerance.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace sffd {

struct CompareTolerance {
  bool bitExact = false;   // strict mode: any difference in the bits is a mismatch
  double maxUlp = 0;       // an element passes when within maxUlp ...
  double absOfScale = 0;   // ... or when |a-b| <= absOfScale * (largest |value| in the buffer)
};

struct CompareResult {
  double maxAbs = 0;
  uint64_t maxUlp = 0;
  size_t mismatched = 0, total = 0;
  size_t firstMismatch = SIZE_MAX;   // index of the first element outside the tolerance (sffd conform names it)
};

// The tolerance between two devices' outputs of one kernel (docs/CONFORMANCE.md "Tolerances"): `buffer` is
// the output's name as sffd conform gives it ("pn.records", "clip.records", "deform.patches", ...).
CompareTolerance crossDeviceTolerance(std::string_view buffer, bool strict, bool f64);

// Values are compared in the precision the kernel wrote (float32 when `float32`, else double); the
// CPU reference's double values are rounded to float32 first when compared with float32 output.
CompareResult compareBuffers(const std::vector<double>& a, const std::vector<double>& b, bool float32,
                             const CompareTolerance& tol);

// Distance between two values in units in the last place of their type.
uint64_t ulpDistance(float a, float b);
uint64_t ulpDistance(double a, double b);

}  // namespace sffd
