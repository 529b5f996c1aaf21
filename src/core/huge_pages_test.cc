#include "core/huge_pages.h"

#include <gtest/gtest.h>

using namespace sffd;

// The restart asks for huge pages only where the kernel gives them on request, and never overrides or
// repeats a choice already in GLIBC_TUNABLES (so a restarted process does not restart again).
TEST(HugePages, TunablesAddHugetlbOnlyWhereItChangesSomething) {
  EXPECT_EQ(tunablesForHugePages(nullptr, "madvise"), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(tunablesForHugePages("", "madvise"), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(tunablesForHugePages("glibc.malloc.check=3", "madvise"), "glibc.malloc.check=3:glibc.malloc.hugetlb=1");
  EXPECT_EQ(tunablesForHugePages("glibc.malloc.hugetlb=0", "madvise"), std::nullopt);
  EXPECT_EQ(tunablesForHugePages("glibc.malloc.hugetlb=1", "madvise"), std::nullopt);
  EXPECT_EQ(tunablesForHugePages(nullptr, "always"), std::nullopt);
  EXPECT_EQ(tunablesForHugePages(nullptr, "never"), std::nullopt);
}

// Advice on any range, aligned or not, empty or null, leaves the memory as it was.
TEST(HugePages, AdviceKeepsTheContents) {
  std::vector<int> v;
  reserveHuge(v, size_t(3) << 20);
  v.assign(size_t(3) << 20, 7);
  adviseHugePages(v.data() + 1, v.size() * sizeof(int) - 8);
  adviseHugePages(nullptr, 1 << 22);
  adviseHugePages(v.data(), 0);
  EXPECT_EQ(v[0], 7);
  EXPECT_EQ(v.back(), 7);
}
