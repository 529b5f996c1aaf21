// A torus generated in code, and the comparison both examples make: what the application read from
// sffd's device buffer against the CPU device's result, bit for bit.
#pragma once
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include <sffd/sffd.h>

namespace example {

// rings x sides quads, two triangles each; no normals (sffd computes them).
inline sffd::Mesh torus(int rings = 24, int sides = 12, double R = 1.0, double r = 0.35) {
  std::vector<float> xyz;
  std::vector<uint32_t> tris;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < sides; ++j) {
      double u = 2 * M_PI * i / rings, v = 2 * M_PI * j / sides;
      xyz.insert(xyz.end(), {float((R + r * std::cos(v)) * std::cos(u)), float((R + r * std::cos(v)) * std::sin(u)),
                             float(r * std::sin(v))});
      auto at = [&](int a, int b) { return uint32_t((a % rings) * sides + b % sides); };
      tris.insert(tris.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  sffd::MeshView view;
  view.positionsF32 = xyz.data();
  view.vertexCount = xyz.size() / 3;
  view.triangles = tris.data();
  view.triangleCount = tris.size() / 3;
  return sffd::meshFromView(view);
}

// Classic FFD's device output in float: per vertex x, y, z, w, then (from half the chunk's bytes) the
// normals. `bytes` is the chunk as the application read it. Returns the number of differing values.
inline size_t compareClassicChunk(const sffd::OutputChunk& chunk, const std::vector<unsigned char>& bytes,
                                  const sffd::Mesh& expected) {
  size_t bad = 0;
  for (size_t i = 0; i < chunk.count; ++i) {
    float p[4], n[4];
    std::memcpy(p, bytes.data() + 16 * i, 16);
    std::memcpy(n, bytes.data() + bytes.size() / 2 + 16 * i, 16);
    const glm::dvec3 &ep = expected.positions[chunk.first + i], &en = expected.normals[chunk.first + i];
    for (int a = 0; a < 3; ++a) bad += (double(p[a]) != ep[a]) + (double(n[a]) != en[a]);
  }
  return bad;
}

}  // namespace example
