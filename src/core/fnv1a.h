// FNV-1a, 64 bits: a quick, dependency-free fingerprint of bytes (conformance dumps' inputs, the shader
// binary cache's keys and payloads). Not a defence against someone crafting collisions.
#pragma once
#include <cstddef>
#include <cstdint>

namespace sffd {

constexpr uint64_t kFnv1aSeed = 1469598103934665603ull;

// Continues the hash `h` over `bytes` bytes at `data` (start with kFnv1aSeed).
inline uint64_t fnv1a64(const void* data, size_t bytes, uint64_t h = kFnv1aSeed) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

}  // namespace sffd
