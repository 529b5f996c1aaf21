// The kernels against the OpenGL ES 3.1 minimum limits (gl_es_limits.h), asked of the compiled
// programs on the gles backend: active storage blocks and their binding indices, uniform block sizes,
// the work-group size; shared memory from the ES source (GL has no per-program query for it).
#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <regex>
#include <string>

#include <sffd/error.h>
#include "backends/opengl/gl_backend.h"
#include "backends/opengl/gl_context.h"
#include "backends/opengl/gl_es_limits.h"
#include "core/kernel_registry.h"

namespace sffd::gl {
namespace {

const bool kSoftware = [] {
  setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
  return true;
}();

// Kernels that still bind more storage blocks than ES 3.1 guarantees, with the count they use
// (docs/GLES.md, "Limits"): the gles backend refuses them unless SFFD_GLES_LIMITS=device. A ratchet:
// a kernel that uses more than its entry, or a kernel not listed that uses more than 4, fails; so
// does an entry that is no longer needed (lower it when a kernel's bindings are merged).
const std::map<std::string, int> kOverStorageLimit = {};

std::unique_ptr<Backend> openGles(bool deviceLimits) {
  if (!providerLibraryPresent(Provider::EGLES)) return nullptr;
  Options o;
  o.provider = Provider::EGLES;
  o.deviceLimits = deviceLimits;
  try {
    return createBackend(o);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Device) throw;
    return nullptr;
  }
}

TEST(GlesLimits, EveryKernelWithinTheEs31MinimumLimits) {
  unsetenv("SFFD_GLES_LIMITS");
  auto b = openGles(true);   // the device's own limits, so that every program links and can be measured
  if (!b) GTEST_SKIP() << "no OpenGL ES 3.1 context here";
  const std::regex sharedDecl(R"((^|\n)\s*shared\s)");
  for (const EmbeddedKernel& k : embeddedKernels()) {
    EXPECT_FALSE(std::regex_search(k.gles, sharedDecl)) << k.name << " declares shared memory";
    for (bool strict : {false, true}) {
      const ProgramResources& r = programResources(*b, k.name, {strict, false});
      auto over = kOverStorageLimit.find(k.name);
      const int allowedBlocks = over == kOverStorageLimit.end() ? es31::kMaxComputeStorageBlocks : over->second;
      SCOPED_TRACE(std::string(k.name) + (strict ? " strict" : " fast") + ": " + std::to_string(r.storageBlocks) +
                   " storage blocks, highest binding " + std::to_string(r.maxStorageBinding) + ", uniform block " +
                   std::to_string(r.maxUniformBlockBytes) + " bytes");
      if (over == kOverStorageLimit.end()) {
        EXPECT_LE(r.storageBlocks, es31::kMaxComputeStorageBlocks);
        EXPECT_LT(r.maxStorageBinding, es31::kMaxStorageBindings);
      } else {
        EXPECT_EQ(r.storageBlocks, allowedBlocks) << "update kOverStorageLimit";
      }
      EXPECT_LE(r.maxUniformBlockBytes, es31::kMaxUniformBlockSize);
      int invocations = 1;
      for (int i = 0; i < 3; ++i) {
        EXPECT_GE(r.groupSize[i], 1);
        EXPECT_LE(r.groupSize[i], es31::kMaxGroupSize[i]);
        invocations *= r.groupSize[i];
      }
      EXPECT_LE(invocations, es31::kMaxInvocations);
    }
  }
}

// By default the backend reports the minimum limits, has no doubles, and refuses a kernel past them
// with a device error naming the limit and the way out.
TEST(GlesLimits, HeldToTheMinimumByDefault) {
  unsetenv("SFFD_GLES_LIMITS");
  auto b = openGles(false);
  if (!b) GTEST_SKIP() << "no OpenGL ES 3.1 context here";
  const DeviceInfo& info = b->info();
  EXPECT_EQ(info.api, "gles");
  EXPECT_FALSE(info.limits.float64);
  EXPECT_LE(info.limits.maxStorageBufferRange, es31::kMaxStorageBlockSize);
  for (uint32_t n : info.limits.maxWorkGroupCount) EXPECT_LE(n, es31::kMaxGroupCount);
  for (const EmbeddedKernel& k : embeddedKernels()) {
    if (kOverStorageLimit.count(k.name)) {
      try {
        programResources(*b, k.name, {true, false});
        ADD_FAILURE() << k.name << " was built past the storage-block minimum";
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device) << e.what();
        EXPECT_NE(std::string(e.what()).find("SFFD_GLES_LIMITS=device"), std::string::npos) << e.what();
      }
    } else {
      EXPECT_LE(programResources(*b, k.name, {true, false}).storageBlocks, es31::kMaxComputeStorageBlocks) << k.name;
    }
  }
  // The environment chooses too, and a bad value is a usage error.
  setenv("SFFD_GLES_LIMITS", "device", 1);
  auto own = openGles(false);
  ASSERT_TRUE(own);
  if (!kOverStorageLimit.empty()) {
    const auto& [name, blocks] = *kOverStorageLimit.begin();
    EXPECT_EQ(programResources(*own, name, {true, false}).storageBlocks, blocks);
  }
  setenv("SFFD_GLES_LIMITS", "phone", 1);
  Options o;
  o.provider = Provider::EGLES;
  try {
    createBackend(o);
    ADD_FAILURE() << "SFFD_GLES_LIMITS=phone accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
  }
  unsetenv("SFFD_GLES_LIMITS");
}

}  // namespace
}  // namespace sffd::gl
