// What the backend tests share: which backends every parameterised test runs on, opening one with
// validation on, gtest-safe names for them, and the CPU backend as the reference.
#pragma once
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "backends/backend_select.h"
#include "backends/cpu/cpu_backend.h"

namespace sffd::testing {

// Backends that must be present: by default every one Debian 12's Mesa gives and the CPU backend
// (SFFD_REQUIRE_BACKENDS overrides).
inline std::vector<std::string> requiredBackends() {
  const char* env = std::getenv("SFFD_REQUIRE_BACKENDS");
  std::stringstream ss(env ? env : "vulkan,gl-egl,gl-osmesa,cpu");
  std::vector<std::string> names;
  for (std::string n; std::getline(ss, n, ',');)
    if (!n.empty()) names.push_back(n);
  return names;
}

// The backend of that name with Vulkan validation on; gles held to the ES 3.1 minimum limits, within
// which every kernel fits (gles_limits_test.cc).
inline OpenedBackend openForTest(const std::string& name) {
  BackendRequest r;
  r.name = name;
  r.validation = true;
  return openBackend(r);
}

// The CPU backend, shared by a test program's tests: the reference the other backends are compared with.
inline Backend& cpuBackend() {
  static const std::unique_ptr<Backend> backend = cpu::createBackend();
  return *backend;
}

// "gl-egl" -> "gl_egl": a test-name suffix for INSTANTIATE_TEST_SUITE_P.
inline std::string backendTestName(std::string n) {
  for (char& c : n)
    if (c == '-') c = '_';
  return n;
}

}  // namespace sffd::testing
