// What the backend tests share: which backends every parameterised test runs on, opening one with
// validation on, and gtest-safe names for them.
#pragma once
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "backends/backend_select.h"

namespace sffd::testing {

// Backends that must be present: by default every one Debian 12's Mesa gives (SFFD_REQUIRE_BACKENDS overrides).
inline std::vector<std::string> requiredBackends() {
  const char* env = std::getenv("SFFD_REQUIRE_BACKENDS");
  std::stringstream ss(env ? env : "vulkan,gl-egl,gl-osmesa");
  std::vector<std::string> names;
  for (std::string n; std::getline(ss, n, ',');)
    if (!n.empty()) names.push_back(n);
  return names;
}

// The backend of that name with Vulkan validation on.
inline OpenedBackend openForTest(const std::string& name) {
  BackendRequest r;
  r.name = name;
  r.validation = true;
  return openBackend(r);
}

// "gl-egl" -> "gl_egl": a test-name suffix for INSTANTIATE_TEST_SUITE_P.
inline std::string backendTestName(std::string n) {
  for (char& c : n)
    if (c == '-') c = '_';
  return n;
}

}  // namespace sffd::testing
