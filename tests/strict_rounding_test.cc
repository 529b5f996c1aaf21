// The strict kernels' rounding fix-up (kernels/common/correctly_rounded.h) on the drivers here. llvmpipe
// and lavapipe round a / b and sqrt exactly, so they skip it unless SFFD_STRICT_ROUNDING=fixup forces it:
// forced, the GLSL of the fix-up must leave their exact results alone, in float and in double, so that
// the strict bits equal the CPU twin's as they do on a GPU that needs it.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "tests/support/cli_runner.h"

namespace {
using namespace sffd::test;
const std::string kData = SFFD_TEST_DATA;

void expectStrictBitsWithFixup(const std::string& job, bool f64 = false) {
  if (!usable("vulkan") || !usable("gl-egl")) GTEST_SKIP() << "compares vulkan and gl-egl with the CPU; this machine lacks one";
  RunResult r = runSffd("conform " + job + " --strict --backends vulkan,gl-egl,gles,cpu",
                        "SFFD_STRICT_ROUNDING=fixup SFFD_TRACE_COMPILE=1");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("conform: PASS"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("max_ulp=1"), std::string::npos) << r.out;
  // The kernels were compiled with the fix-up (SFFD_ASSUME_LOOSE_DIVISION, 0x80).
  EXPECT_TRUE(std::regex_search(r.err, std::regex("compile vulkan \\w+ strict f(32|64) assuming 0x[89a-f][0-9a-f]\\b"))) << r.err;
  // (NVIDIA's GL runs no doubles: conform skips gl-egl there, docs/CONFORMANCE.md.)
  if (!f64 || hasDoubles("gl-egl")) {
    EXPECT_TRUE(std::regex_search(r.err, std::regex("compile gl \\w+ strict f(32|64) assuming 0x[89a-f][0-9a-f]\\b"))) << r.err;
  }
}

TEST(StrictRounding, ForcedFixupKeepsTheCpuBitsInFloat) {
  expectStrictBitsWithFixup(kData + "/cube2.obj -l " + kData + "/lattices/cube2_twist.npy --edge-length 0.3");
  expectStrictBitsWithFixup(kData + "/sphere.obj -l " + kData + "/lattices/sphere_twist.npy --method accurate");
}

TEST(StrictRounding, ForcedFixupKeepsTheCpuBitsInDouble) {
  expectStrictBitsWithFixup(kData + "/cube2.obj -l " + kData + "/lattices/cube2_twist.npy --edge-length 0.3 --precision double", true);
}

}  // namespace
