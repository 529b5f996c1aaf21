// The strict kernels' rounding fix-up (correctly_rounded.h, the same source the GLSL compiles), fed
// approximations up to 4 ulp off, as drivers that do not round a / b and sqrt exactly give them.
#include "kernels/common/correctly_rounded_twin.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

namespace {
using namespace sffd::kernels::rounded;

template <class T> T stepUlps(T x, int k) {
  for (; k > 0; --k) x = std::nextafter(x, std::numeric_limits<T>::infinity());
  for (; k < 0; ++k) x = std::nextafter(x, -std::numeric_limits<T>::infinity());
  return x;
}

template <class T> auto bits(T x) {
  if constexpr (sizeof(T) == 4) return std::bit_cast<uint32_t>(x);
  else return std::bit_cast<uint64_t>(x);
}

// Random finite values over a wide exponent range, both signs, with a share of short significands
// (small integers, exact thirds' neighbours) where quotients land near binade edges.
template <class T> T randomValue(std::mt19937_64& rng) {
  std::uniform_real_distribution<T> mant(1, 2);
  std::uniform_int_distribution<int> expo(-60, 60), small(1, 64), kind(0, 3);
  T v = kind(rng) == 0 ? T(small(rng)) : std::ldexp(mant(rng), expo(rng));
  return (rng() & 1) ? -v : v;
}

template <class T> void checkQuotients(int samples) {
  std::mt19937_64 rng(12345);
  int checked = 0;
  for (int i = 0; i < samples; ++i) {
    T a = randomValue<T>(rng), b = randomValue<T>(rng);
    T exact = a / b;
    for (int k = -4; k <= 4; ++k) {
      T q = stepUlps(exact, k);
      if (!std::isnormal(q) || std::signbit(q) != std::signbit(exact)) continue;
      ASSERT_EQ(bits(sffdRoundedQuotient(a, b, q)), bits(exact)) << a << " / " << b << " from " << k << " ulp";
      ++checked;
    }
  }
  EXPECT_GT(checked, samples * 8);
}

template <class T> void checkRoots(int samples) {
  std::mt19937_64 rng(678);
  for (int i = 0; i < samples; ++i) {
    T x = std::abs(randomValue<T>(rng));
    T exact = std::sqrt(x);
    for (int k = -4; k <= 4; ++k)
      ASSERT_EQ(bits(sffdRoundedRoot(x, stepUlps(exact, k))), bits(exact)) << "sqrt " << x << " from " << k << " ulp";
  }
}

TEST(CorrectlyRounded, FloatQuotientsFromApproximations) { checkQuotients<float>(200000); }
TEST(CorrectlyRounded, DoubleQuotientsFromApproximations) { checkQuotients<double>(100000); }
TEST(CorrectlyRounded, FloatRootsFromApproximations) { checkRoots<float>(200000); }
TEST(CorrectlyRounded, DoubleRootsFromApproximations) { checkRoots<double>(100000); }

// A double quotient or root no better than a float's, as a driver may give it, is still rounded right.
TEST(CorrectlyRounded, DoublesFromFloatPrecision) {
  std::mt19937_64 rng(91);
  for (int i = 0; i < 100000; ++i) {
    double a = randomValue<double>(rng), b = randomValue<double>(rng), x = std::abs(a);
    ASSERT_EQ(bits(sffdRoundedQuotient(a, b, double(float(a / b)))), bits(a / b)) << a << " / " << b;
    ASSERT_EQ(bits(sffdRoundedRoot(x, double(float(std::sqrt(x))))), bits(std::sqrt(x))) << "sqrt " << x;
  }
}

// The same over the whole double range, a third of the divisors 2^1022 or more (their reciprocals are
// subnormal, which the strict Newton steps avoid): a float-precision error, in double's own range.
TEST(CorrectlyRounded, DoublesFromFloatPrecisionOverTheWholeRange) {
  std::mt19937_64 rng(1022);
  std::uniform_real_distribution<double> mant(1, 2), error(-1, 1);
  std::uniform_int_distribution<int> expo(-1020, 1023), high(1022, 1023), pick(0, 2);
  int checked = 0;
  for (int i = 0; i < 100000; ++i) {
    double a = std::ldexp(mant(rng), expo(rng)), b = std::ldexp(mant(rng), pick(rng) == 0 ? high(rng) : expo(rng));
    if (rng() & 1) b = -b;
    const double q = a / b;
    // Quotients near the ends of the range are returned as the driver gave them.
    if (!(std::abs(q) >= 0x1p-1020 && std::abs(q) <= 0x1p1020)) continue;
    const double approx = q * (1 + 0x1p-23 * error(rng));
    ASSERT_EQ(bits(sffdRoundedQuotient(a, b, approx)), bits(q)) << a << " / " << b << " from " << approx;
    const double x = std::abs(a);
    ASSERT_EQ(bits(sffdRoundedRoot(x, std::sqrt(x) * (1 + 0x1p-23 * error(rng)))), bits(std::sqrt(x))) << "sqrt " << x;
    ++checked;
  }
  EXPECT_GT(checked, 50000);
}

// Exact results at binade edges, approached from below (the neighbour below has half the ulp).
TEST(CorrectlyRounded, ExactPowersOfTwoFromBelow) {
  for (float p : {0.25f, 1.0f, 2.0f, 1024.0f}) {
    EXPECT_EQ(sffdRoundedQuotient(p * 3.0f, 3.0f, stepUlps(p, -3)), p);
    EXPECT_EQ(sffdRoundedRoot(p * p, stepUlps(p, -3)), p);
  }
  for (double p : {0.5, 1.0, 4096.0}) {
    EXPECT_EQ(sffdRoundedQuotient(p * 7.0, 7.0, stepUlps(p, -3)), p);
    EXPECT_EQ(sffdRoundedRoot(p * p, stepUlps(p, -3)), p);
  }
}

// What no driver rounds differently is passed through as the driver gave it.
TEST(CorrectlyRounded, SpecialOperandsAreTheDriversResult) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const float tiny = std::numeric_limits<float>::denorm_min();
  EXPECT_EQ(sffdRoundedQuotient(0.0f, 3.0f, 0.0f), 0.0f);
  EXPECT_EQ(sffdRoundedQuotient(1.0f, 0.0f, inf), inf);
  EXPECT_TRUE(std::isnan(sffdRoundedQuotient(nan, 1.0f, nan)));
  EXPECT_EQ(sffdRoundedQuotient(tiny, 3.0f, 0.0f), 0.0f);  // a subnormal result a driver may flush
  EXPECT_TRUE(std::isnan(sffdRoundedRoot(-1.0f, nan)));
  EXPECT_EQ(sffdRoundedRoot(0.0f, 0.0f), 0.0f);
  EXPECT_EQ(sffdRoundedRoot(inf, inf), inf);
  EXPECT_EQ(sffdRoundedQuotient(1.0, 0.0, std::numeric_limits<double>::infinity()), std::numeric_limits<double>::infinity());
  EXPECT_EQ(sffdRoundedRoot(0.0, 0.0), 0.0);
}

}  // namespace
