#include "core/key3_map.h"

#include <map>
#include <random>

#include <gtest/gtest.h>

namespace sffd {
namespace {

// Keys from a small range, so that many repeat; the all-zero key among them.
Key3 someKey(std::mt19937_64& rng) {
  std::uniform_int_distribution<uint64_t> word(0, 3);
  return {word(rng), word(rng), word(rng) << 60};
}

TEST(Key3Map, GivesEachKeyItsFirstValueAsAMapWould) {
  for (size_t expected : {size_t(0), size_t(1), size_t(1000)}) {
    std::mt19937_64 rng(7);
    Key3Map map(expected);   // 0 and 1: the table grows many times
    std::map<Key3, uint32_t> reference;
    for (uint32_t i = 0; i < 5000; ++i) {
      const Key3 k = someKey(rng);
      const uint32_t want = reference.emplace(k, i).first->second;
      ASSERT_EQ(map.of(k, i), want) << "expected " << expected << ", key " << i;
    }
    ASSERT_EQ(reference.size(), 64u);
    EXPECT_TRUE(reference.count(Key3{0, 0, 0}));
    for (const auto& [k, v] : reference) EXPECT_EQ(map.of(k, ~0u), v);
  }
}

TEST(Key3Map, TheAllZeroKeyIsAKeyLikeAnyOther) {
  Key3Map map(4);
  EXPECT_EQ(map.of({0, 0, 0}, 5), 5u);
  EXPECT_EQ(map.of({0, 0, 0}, 6), 5u);
  EXPECT_EQ(map.of({0, 0, 1}, 7), 7u);
  map.of({0, 0, 0}, 0) = 9;   // the reference is the value
  EXPECT_EQ(map.of({0, 0, 0}, 0), 9u);
}

TEST(Key3Map, RemapRenumbersAndForgets) {
  constexpr uint32_t kNone = ~0u;
  Key3Map map(2);
  for (uint32_t i = 0; i < 100; ++i) map.of({i, 0, 0}, i);   // key {0,0,0} has value 0
  std::vector<uint32_t> to(100, kNone);
  for (uint32_t i = 0; i < 100; i += 3) to[i] = 1000 + i;   // keeps 0, 3, 6, ...
  map.remap(to, kNone);
  for (uint32_t i = 0; i < 100; ++i) EXPECT_EQ(map.of({i, 0, 0}, 7), i % 3 == 0 ? 1000 + i : 7u) << i;
  // Forgetting the all-zero key too.
  std::vector<uint32_t> none(2000, kNone);
  map.remap(none, kNone);
  EXPECT_EQ(map.of({0, 0, 0}, 42), 42u);
}

}  // namespace
}  // namespace sffd
