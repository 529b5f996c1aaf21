// Shared by the fuzz targets: a reader's result must be well formed, and the only exception that may
// leave a reader is an input Error (what `sffd` turns into "sffd: error: file:line: what", exit 2).
// Anything else (another exception, a crash, a sanitizer report, a hang, a huge allocation) is a bug
// for libFuzzer to report.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <sffd/error.h>
#include "model/mesh.h"

namespace sffd::fuzz {

[[noreturn]] inline void fail(const char* what) {
  std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
  std::abort();
}

inline bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// What every consumer of a Mesh relies on (mesh.h).
inline void checkMesh(const Mesh& m) {
  const size_t n = m.positions.size();
  if (m.triangles.empty()) fail("a mesh without triangles was accepted");
  if (m.normals.size() != n || m.weldId.size() != n) fail("normals or weldId do not match the vertex count");
  for (const auto& t : m.triangles)
    for (uint32_t i : t)
      if (i >= n) fail("triangle index out of range");
  for (size_t v = 0; v < n; ++v) {
    if (!finite(m.positions[v])) fail("non-finite position accepted");
    if (!finite(m.normals[v]) || std::abs(glm::length(m.normals[v]) - 1.0) > 1e-6) fail("normal not finite and unit");
    if (m.weldId[v] > v) fail("weldId refers forward");
  }
}

// Runs a reader; an input Error is the expected way to refuse, anything else escapes to libFuzzer.
template <class F>
void expectReadOrInputError(F&& read) {
  try {
    read();
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Input) fail(e.what());
    const std::string what = e.what();
    if (what.empty() || what.find('\n') != std::string::npos) fail("an error message must be one line");
  }
}

}  // namespace sffd::fuzz
