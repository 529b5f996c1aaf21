// What the backend tests share: which backends every parameterised test runs on, opening one with
// validation on (or skipping where this machine has none), gtest-safe names for them, the CPU
// backend as the reference, the error kind a call throws, and the classic kernel's hand-built inputs.
#pragma once
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <sffd/error.h>
#include "backends/backend_select.h"
#include "backends/cpu/cpu_backend.h"

namespace sffd::testing {

// The backends the parameterised tests run on: every one Debian 12's Mesa gives, and the CPU backend.
inline std::vector<std::string> testBackends() { return {"vulkan", "gl-egl", "gl-osmesa", "cpu"}; }

// Whether this machine must have `name`: SFFD_REQUIRE_BACKENDS lists them (ctest sets it from
// SFFD_TEST_REQUIRE_BACKENDS, tests/CMakeLists.txt); unset, none is required.
inline bool requiredHere(const std::string& name) {
  const char* env = std::getenv("SFFD_REQUIRE_BACKENDS");
  std::stringstream ss(env ? env : "");
  for (std::string n; std::getline(ss, n, ',');)
    if (n == name) return true;
  return false;
}

// open(name), or nothing when this machine has no such device (a device error) and does not require it:
// `why` then says so, and the caller skips that backend. Any other error is thrown.
template <class Open>
auto openUnlessAbsent(const std::string& name, Open&& open, std::string& why) -> std::optional<decltype(open(name))> {
  try {
    return open(name);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Device || requiredHere(name)) throw;
    why = name + " cannot be opened here: " + e.what();
    std::printf("skipping %s\n", why.c_str());
    return std::nullopt;
  }
}

// The backend of that name with Vulkan validation on; gles held to the ES 3.1 minimum limits, within
// which every kernel fits (gles_limits_test.cc).
inline OpenedBackend openForTest(const std::string& name) {
  BackendRequest r;
  r.name = name;
  r.validation = true;
  return openBackend(r);
}

// `names` less those this machine has no device for (and does not require), each opened once a process to see.
inline std::vector<std::string> backendsHere(const std::vector<std::string>& names) {
  static std::map<std::string, bool> here;
  std::vector<std::string> kept;
  for (const std::string& n : names) {
    if (!here.count(n)) {
      std::string why;
      here[n] = openUnlessAbsent(n, openForTest, why).has_value();
    }
    if (here[n]) kept.push_back(n);
  }
  return kept;
}

// Skips the test when this machine cannot open backend `name` (and does not require it).
#define SFFD_SKIP_WITHOUT(name) \
  if (sffd::testing::backendsHere({name}).empty()) GTEST_SKIP() << name << " cannot be opened here"

// Declares `var`, the backend `name` opened for a test, or skips the test when this machine has none.
#define SFFD_OPEN_OR_SKIP(var, name)                                                                \
  std::string var##Why_;                                                                            \
  auto var##Opened_ = sffd::testing::openUnlessAbsent(name, sffd::testing::openForTest, var##Why_); \
  if (!var##Opened_) GTEST_SKIP() << var##Why_;                                                     \
  OpenedBackend var = std::move(*var##Opened_)

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

// Error kind of what `f` throws; a failure when it throws nothing or something other than an sffd::Error.
template <class F>
std::optional<ErrorKind> errorKindOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_FALSE(std::string(e.what()).empty());
    return e.kind();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an sffd::Error: " << e.what();
    return std::nullopt;
  }
  ADD_FAILURE() << "nothing was thrown";
  return std::nullopt;
}

}  // namespace sffd::testing
