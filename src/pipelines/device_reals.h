// Host arrays of doubles to and from device buffers of the kernels' `real` (float or double), and
// buffers owned by a pipeline object (destroyed with it).
#pragma once
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/backend.h"

namespace sffd {

// The reals of a host array in the kernel's storage type, as bytes.
inline std::vector<unsigned char> realBytes(const std::vector<double>& v, bool f64) {
  std::vector<unsigned char> out(v.size() * (f64 ? 8 : 4));
  if (f64) {
    if (!out.empty()) std::memcpy(out.data(), v.data(), out.size());
  } else {
    for (size_t i = 0; i < v.size(); ++i) {
      float f = float(v[i]);
      std::memcpy(&out[4 * i], &f, 4);
    }
  }
  return out;
}

inline std::vector<double> doublesOf(const std::vector<unsigned char>& bytes, bool f64) {
  std::vector<double> out(bytes.size() / (f64 ? 8 : 4));
  if (f64) {
    if (!out.empty()) std::memcpy(out.data(), bytes.data(), out.size() * 8);
  } else {
    for (size_t i = 0; i < out.size(); ++i) {
      float f;
      std::memcpy(&f, &bytes[4 * i], 4);
      out[i] = f;
    }
  }
  return out;
}

inline uint64_t alignUp(uint64_t bytes, uint64_t alignment) {
  return alignment > 1 ? (bytes + alignment - 1) / alignment * alignment : bytes;
}

// The buffers a pipeline object made, destroyed with it (also when its constructor throws half way).
struct OwnedBuffers {
  Backend& backend;
  std::vector<BufferId> ids;
  explicit OwnedBuffers(Backend& b) : backend(b) {}
  OwnedBuffers(const OwnedBuffers&) = delete;
  OwnedBuffers& operator=(const OwnedBuffers&) = delete;
  ~OwnedBuffers() {
    for (BufferId id : ids) backend.destroyBuffer(id);
  }
};

// A buffer of at least 16 bytes (no buffer is empty).
inline BufferId makeBuffer(OwnedBuffers& owned, uint64_t bytes) {
  BufferId id = owned.backend.createBuffer(bytes < 16 ? 16 : bytes);
  owned.ids.push_back(id);
  return id;
}

inline BufferId uploadReals(OwnedBuffers& owned, const std::vector<double>& v, bool f64) {
  Backend& backend = owned.backend;
  std::vector<unsigned char> b = realBytes(v, f64);
  BufferId id = makeBuffer(owned, b.size());
  if (!b.empty()) backend.upload(id, 0, b.data(), b.size());
  return id;
}

// `count` reals from `offset` bytes into the buffer, widened to double.
inline std::vector<double> downloadReals(Backend& backend, BufferId buffer, uint64_t offset, size_t count, bool f64) {
  std::vector<unsigned char> b(count * (f64 ? 8 : 4));
  if (!b.empty()) backend.download(buffer, offset, b.data(), b.size());
  return doublesOf(b, f64);
}

// The same into `out` (room for `count`): doubles read in place, floats through `scratch` (kept by the
// caller across calls) and widened once; no other copy.
inline void downloadRealsInto(Backend& backend, BufferId buffer, uint64_t offset, size_t count, bool f64, double* out,
                              std::vector<float>& scratch) {
  if (!count) return;
  if (f64) {
    backend.download(buffer, offset, out, count * 8);
    return;
  }
  if (scratch.size() < count) scratch.resize(count);
  backend.download(buffer, offset, scratch.data(), count * 4);
  for (size_t i = 0; i < count; ++i) out[i] = scratch[i];
}

}  // namespace sffd
