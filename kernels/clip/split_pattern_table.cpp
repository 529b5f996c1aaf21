// Lu & Feng, improved smooth FFD: the crack-free split-pattern table (METHOD.md 4.2). The data
// is generated at build time by tools/split_pattern_gen.cpp (build/generated/split_patterns.cpp).
#include "kernels/clip/split_pattern_table.h"

namespace sffd {

extern constinit const SplitPatternTable kGeneratedSplitPatternTable;

const SplitPattern& SplitPatternTable::pattern(int a, int b, int c) const {
  static constexpr SplitPattern kEmpty{0, 0, 0, 0};
  if (a < 1 || c > nmax_ || a > b || b > c) return kEmpty;
  return patterns_[splitPatternKey(nmax_, a, b, c)];  // c > a + b: an empty entry
}

const SplitPatternTable& splitPatternTable() { return kGeneratedSplitPatternTable; }

}  // namespace sffd
