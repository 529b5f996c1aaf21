// A hash map from keys of three 64-bit words (a position's or normal's bits, an edge and a barycentric)
// to a 32-bit value, by open addressing with linear probing in one flat table: no allocation a key, as the
// node-based std::unordered_map makes (its allocations and frees were a sixth of reading a 1 M triangle
// OBJ), and a rehash reuses the storage the last table left: a streamed weld rehashes every compaction,
// and fresh storage each time cost more in page faults and the kernel's zeroing than the weld itself.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "core/huge_pages.h"

namespace sffd {

using Key3 = std::array<uint64_t, 3>;

class Key3Map {
 public:
  // `expected`: about how many keys will come (the first table holds twice as many slots; it grows).
  explicit Key3Map(size_t expected) : expected_(expected) {}

  // The value of `key`; a new key gets `fresh`. The reference stays valid until the next of() or remap().
  // Inline, the rare cases apart: the weld asks it for most of a patch's boundary vertices.
  uint32_t& of(const Key3& key, uint32_t fresh) {
    if (same(key, kEmpty) || 2 * (used_ + 1) > slots_.size()) return ofRare(key, fresh);
    return insert(key, fresh);
  }

  // Keeps the keys whose value v has a new value to[v] (`none`: the key goes), in a table sized for them,
  // or for `room` keys if more (those expected before the next remap: a growth rehashes them all).
  void remap(const std::vector<uint32_t>& to, uint32_t none, size_t room = 0) {
    if (hasZero_) hasZero_ = to[zeroValue_] != none, zeroValue_ = to[zeroValue_];
    size_t kept = 0;
    for (const Slot& s : slots_) kept += !same(s.key, kEmpty) && to[s.value] != none;
    size_t n = 16;
    while (n < 2 * std::max(2 * kept, room)) n *= 2;
    emptyTable(n);
    used_ = kept;
    for (const Slot& s : spare_)
      if (!same(s.key, kEmpty) && to[s.value] != none) *find(s.key) = {s.key, to[s.value]};
  }

 private:
  struct Slot {
    Key3 key{0, 0, 0};
    uint32_t value = 0;
  };
  static constexpr Key3 kEmpty{0, 0, 0};
  static size_t hash(const Key3& k) {
    uint64_t h = k[0] * 0x9E3779B97F4A7C15ull;
    h = (h ^ (h >> 29) ^ k[1]) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 31) ^ k[2]) * 0x94D049BB133111EBull;
    return size_t(h ^ (h >> 32));
  }
  uint32_t& insert(const Key3& key, uint32_t fresh) {
    Slot* s = find(key);
    if (same(s->key, kEmpty)) s->key = key, s->value = fresh, ++used_;
    return s->value;
  }
  // of() for the all-zero key, the first key and a key that needs a larger table.
  [[gnu::noinline]] uint32_t& ofRare(const Key3& key, uint32_t fresh) {
    if (same(key, kEmpty)) {   // the all-zero key (+0.0, +0.0, +0.0) marks empty slots: kept beside them
      if (!hasZero_) hasZero_ = true, zeroValue_ = fresh;
      return zeroValue_;
    }
    if (slots_.empty()) {   // allocated at the first key (a weld that forgets locations expects fewer)
      size_t n = 16;
      while (n < 2 * expected_) n *= 2;
      resizeHuge(slots_, n);
    }
    if (2 * (used_ + 1) > slots_.size()) grow();
    return insert(key, fresh);
  }
  Slot* find(const Key3& key) {
    const size_t mask = slots_.size() - 1;
    for (size_t i = hash(key) & mask;; i = (i + 1) & mask)
      if (same(slots_[i].key, key) || same(slots_[i].key, kEmpty)) return &slots_[i];
  }
  void grow() {
    emptyTable(slots_.size() * 2);
    for (const Slot& s : spare_)
      if (!same(s.key, kEmpty)) *find(s.key) = s;
  }
  // slots_ becomes n empty slots in the spare storage, spare_ the table it was.
  void emptyTable(size_t n) {
    if (spare_.capacity() < n) {
      freeStorage(spare_);
      reserveHuge(spare_, n);
    }
    spare_.assign(n, Slot{});
    spare_.swap(slots_);
  }
  // std::array's == calls memcmp here, a call for each probe.
  static bool same(const Key3& a, const Key3& b) { return ((a[0] ^ b[0]) | (a[1] ^ b[1]) | (a[2] ^ b[2])) == 0; }

  std::vector<Slot> slots_, spare_;
  size_t expected_, used_ = 0;
  bool hasZero_ = false;
  uint32_t zeroValue_ = 0;
};

}  // namespace sffd
