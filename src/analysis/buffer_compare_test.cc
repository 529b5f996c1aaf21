#include "analysis/buffer_compare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace sffd {
namespace {

CompareTolerance strict() {
  CompareTolerance t;
  t.bitExact = true;
  return t;
}

TEST(BufferCompare, StrictIsBitExactSaveForFlushedSubnormals) {
  const float sub = -1.10454185e-38f;   // what the CPU computed where an NVIDIA GPU stored 0
  ASSERT_LT(std::abs(sub), std::numeric_limits<float>::min());
  EXPECT_EQ(compareBuffers({0.5, 0.25}, {0.5, 0.25}, true, strict()).mismatched, 0u);
  EXPECT_EQ(compareBuffers({0.5}, {std::nextafter(0.5f, 1.0f)}, true, strict()).mismatched, 1u);
  EXPECT_EQ(compareBuffers({sub, -0.0}, {0.0, 0.0}, true, strict()).mismatched, 0u);
  // The smallest normal is a value of its own.
  EXPECT_EQ(compareBuffers({std::numeric_limits<float>::min()}, {0.0}, true, strict()).mismatched, 1u);
  EXPECT_EQ(compareBuffers({1e-310}, {0.0}, false, strict()).mismatched, 0u);
  EXPECT_EQ(compareBuffers({1e-300}, {0.0}, false, strict()).mismatched, 1u);
}

TEST(BufferCompare, FastPassesWithinUlpsOrAFractionOfTheScale) {
  CompareTolerance t;
  t.maxUlp = 64;
  t.absOfScale = 1e-6;
  const float x = 0.5f;
  EXPECT_EQ(compareBuffers({x}, {std::nextafter(x, 1.0f)}, true, t).mismatched, 0u);
  EXPECT_EQ(compareBuffers({1.0, 1e-3}, {1.0, 1e-3 + 5e-7}, true, t).mismatched, 0u);   // 5e-7 of scale 1
  EXPECT_EQ(compareBuffers({1.0, 1e-3}, {1.0, 1e-3 + 5e-6}, true, t).mismatched, 1u);
}

// One rule for sffd conform and the backend tests: strict and the clip topology exact, fast within a few
// roundings of the largest value, wider where a solve amplifies them (the smooth fit, the accurate solve).
TEST(BufferCompare, CrossDeviceToleranceFollowsTheBuffer) {
  EXPECT_TRUE(crossDeviceTolerance("deform.patches", true, false).bitExact);
  EXPECT_TRUE(crossDeviceTolerance("clip.headers", false, false).bitExact);
  EXPECT_FALSE(crossDeviceTolerance("clip.records", false, false).bitExact);
  EXPECT_EQ(crossDeviceTolerance("clip.records", false, false).absOfScale, 2e-6);
  EXPECT_EQ(crossDeviceTolerance("deform.patches", false, false).absOfScale, 1e-5);
  EXPECT_EQ(crossDeviceTolerance("accurate.patches", false, false).absOfScale, 1e-4);
  EXPECT_EQ(crossDeviceTolerance("deform.patches", false, true).absOfScale, 1e-12);
}

}  // namespace
}  // namespace sffd
