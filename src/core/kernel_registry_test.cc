#include "core/kernel_registry.h"

#include <gtest/gtest.h>

#include <cstdlib>

using namespace sffd;

namespace {
DeviceInfo device(const char* name, const char* driver, const char* api = "vulkan") {
  DeviceInfo d;
  d.name = name;
  d.driver = driver;
  d.api = api;
  return d;
}
}  // namespace

// Rolled record loops only on llvmpipe / lavapipe of Mesa 23 on (Vulkan and GL driver strings as those
// drivers report them); the lattice's assumptions are kept either way.
TEST(KernelRegistry, RolledLoopsOnlyForMesaFrom23OnTheCpu) {
  KernelVariant v;
  v.assumptions = SFFD_ASSUME_DEGREE2;
  const char* llvmpipe = "llvmpipe (LLVM 15.0.6, 256 bits)";
  EXPECT_EQ(forDevice(v, device(llvmpipe, "llvmpipe Mesa 22.3.6 (LLVM 15.0.6), Vulkan 1.3.230")).assumptions, SFFD_ASSUME_DEGREE2);
  EXPECT_EQ(forDevice(v, device(llvmpipe, "4.5 (Core Profile) Mesa 22.3.6")).assumptions, SFFD_ASSUME_DEGREE2);
  EXPECT_EQ(forDevice(v, device(llvmpipe, "Mesa 25.0.7-2~bpo12+1")).assumptions, SFFD_ASSUME_DEGREE2 | SFFD_ASSUME_ROLLED_LOOPS);
  EXPECT_EQ(forDevice(v, device(llvmpipe, "4.5 (Core Profile) Mesa 23.0.0")).assumptions, SFFD_ASSUME_DEGREE2 | SFFD_ASSUME_ROLLED_LOOPS);
  EXPECT_EQ(forDevice(v, device("AMD Radeon RX 7600 (RADV NAVI33)", "Mesa 25.0.7")).assumptions, SFFD_ASSUME_DEGREE2);
  EXPECT_EQ(forDevice(v, device("NVIDIA H100", "550.54.15")).assumptions, SFFD_ASSUME_DEGREE2);
  EXPECT_EQ(forDevice(v, device(llvmpipe, "")).assumptions, SFFD_ASSUME_DEGREE2);
}

// deform_smooth's one-site form (a small one-shot job asks for it) only on lavapipe below Mesa 23: llvmpipe's GL
// keeps its compiled programs, Mesa 23 on has the rolled form and shader binaries, a GPU's driver its pipelines.
TEST(KernelRegistry, OneSampleSiteOnlyOnLavapipeBefore23) {
  KernelVariant v;
  v.assumptions = SFFD_ASSUME_DEGREE2 | SFFD_ASSUME_ONE_SAMPLE_SITE;
  const char* llvmpipe = "llvmpipe (LLVM 15.0.6, 256 bits)";
  const uint32_t asked = SFFD_ASSUME_DEGREE2 | SFFD_ASSUME_ONE_SAMPLE_SITE;
  EXPECT_EQ(forDevice(v, device(llvmpipe, "llvmpipe Mesa 22.3.6 (LLVM 15.0.6), Vulkan 1.3.230")).assumptions, asked);
  EXPECT_EQ(forDevice(v, device(llvmpipe, "4.5 (Core Profile) Mesa 22.3.6", "gl")).assumptions, SFFD_ASSUME_DEGREE2);
  EXPECT_EQ(forDevice(v, device(llvmpipe, "OpenGL ES 3.2 Mesa 22.3.6", "gles")).assumptions, SFFD_ASSUME_DEGREE2);
  EXPECT_EQ(forDevice(v, device(llvmpipe, "llvmpipe Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6), Vulkan 1.4.305")).assumptions,
            SFFD_ASSUME_DEGREE2 | SFFD_ASSUME_ROLLED_LOOPS);
  EXPECT_EQ(forDevice(v, device("AMD Radeon RX 7600 (RADV NAVI33)", "Mesa 22.3.6")).assumptions, SFFD_ASSUME_DEGREE2);
  EXPECT_EQ(forDevice(v, device("NVIDIA H200", "NVIDIA 580.159.04")).assumptions, SFFD_ASSUME_DEGREE2);
}

// Strict variants round a / b and sqrt themselves (SFFD_ASSUME_LOOSE_DIVISION) on every driver but
// llvmpipe and lavapipe, which round them exactly; fast variants never; SFFD_STRICT_ROUNDING overrides.
TEST(KernelRegistry, StrictVariantsRoundDivisionWhereTheDriverDoesNot) {
  ::unsetenv("SFFD_STRICT_ROUNDING");
  KernelVariant fast, strict;
  strict.strict = true;
  const DeviceInfo lavapipe = device("llvmpipe (LLVM 15.0.6, 256 bits)", "llvmpipe Mesa 22.3.6 (LLVM 15.0.6), Vulkan 1.3.230");
  const DeviceInfo nvidia = device("NVIDIA H200", "NVIDIA 580.159.04"), radv = device("AMD Radeon RX 7600 (RADV NAVI33)", "Mesa 25.0.7");
  EXPECT_EQ(forDevice(strict, lavapipe).assumptions, 0u);
  EXPECT_EQ(forDevice(strict, nvidia).assumptions, SFFD_ASSUME_LOOSE_DIVISION);
  EXPECT_EQ(forDevice(strict, radv).assumptions, SFFD_ASSUME_LOOSE_DIVISION);
  EXPECT_EQ(forDevice(fast, nvidia).assumptions, 0u);
  ::setenv("SFFD_STRICT_ROUNDING", "fixup", 1);
  EXPECT_EQ(forDevice(strict, lavapipe).assumptions, SFFD_ASSUME_LOOSE_DIVISION);
  EXPECT_EQ(forDevice(fast, lavapipe).assumptions, 0u);
  ::setenv("SFFD_STRICT_ROUNDING", "driver", 1);
  EXPECT_EQ(forDevice(strict, nvidia).assumptions, 0u);
  ::unsetenv("SFFD_STRICT_ROUNDING");
}

// deform_smooth is embedded compiled for its usual dispatch (a degree-2 lattice and its fit table in the
// parameter block; cmake/Kernels.cmake SFFD_SPECIALIZED_deform_smooth), with and without rolled loops, and in
// the one-site form, in every variant: a Vulkan pipeline of it is made from that module, which has no specialization constant
// left; any other dispatch gets the general module. The bits are those of layout.h, so a renumbering
// there cannot leave the build's forms unused.
TEST(KernelRegistry, DeformSmoothCompiledForItsUsualDispatch) {
  const EmbeddedKernel* k = findKernel("deform_smooth");
  ASSERT_NE(k, nullptr);
  // SPIR-V: OpDecorate (opcode 71, 3 words + literals) %id SpecId (decoration 1).
  auto hasSpecConstant = [](std::span<const uint32_t> spirv) {
    for (size_t i = 5; i < spirv.size();) {
      const uint32_t words = spirv[i] >> 16, opcode = spirv[i] & 0xffffu;
      if (opcode == 71 && words >= 4 && spirv[i + 2] == 1) return true;
      i += words ? words : 1;
    }
    return false;
  };
  const uint32_t usual = SFFD_ASSUME_DEGREE2 | SFFD_ASSUME_LATTICE_IN_PARAMS | SFFD_ASSUME_FIT_IN_PARAMS;
  for (int v = 0; v < 4; ++v) {
    KernelVariant variant;
    variant.strict = v % 2, variant.f64 = v / 2;
    EXPECT_TRUE(hasSpecConstant(spirvFor(*k, variant)));
    for (uint32_t a : {usual, usual | SFFD_ASSUME_ROLLED_LOOPS, usual | SFFD_ASSUME_ONE_SAMPLE_SITE}) {
      variant.assumptions = a;
      const std::span<const uint32_t> s = spirvFor(*k, variant);
      ASSERT_FALSE(s.empty());
      EXPECT_NE(s.data(), k->spirv[v]) << variantName(variant);
      EXPECT_FALSE(hasSpecConstant(s)) << variantName(variant);
    }
    for (uint32_t a : {(usual & ~SFFD_ASSUME_DEGREE2) | SFFD_ASSUME_GENERAL_DEGREE,
                       (usual & ~SFFD_ASSUME_FIT_IN_PARAMS) | SFFD_ASSUME_FIT_IN_STORAGE}) {
      variant.assumptions = a;
      EXPECT_EQ(spirvFor(*k, variant).data(), k->spirv[v]) << variantName(variant);
    }
  }
}

// The kernels with two loop forms and no other assumption (cmake/Kernels.cmake): both forms compiled
// ahead, neither with the specialization constant; other assumptions fall back to the general module.
TEST(KernelRegistry, LoopFormsCompiledAhead) {
  for (const char* name : {"pn_triangles", "clip_count", "clip_write"}) {
    const EmbeddedKernel* k = findKernel(name);
    ASSERT_NE(k, nullptr) << name;
    for (int v = 0; v < 4; ++v) {
      KernelVariant variant;
      variant.strict = v % 2, variant.f64 = v / 2;
      const std::span<const uint32_t> straight = spirvFor(*k, variant);
      variant.assumptions = SFFD_ASSUME_ROLLED_LOOPS;
      const std::span<const uint32_t> rolled = spirvFor(*k, variant);
      ASSERT_FALSE(straight.empty()) << name;
      ASSERT_FALSE(rolled.empty()) << name;
      EXPECT_NE(straight.data(), k->spirv[v]) << name;
      EXPECT_NE(rolled.data(), k->spirv[v]) << name;
      EXPECT_NE(straight.data(), rolled.data()) << name;
      variant.assumptions = SFFD_ASSUME_DEGREE2;
      EXPECT_EQ(spirvFor(*k, variant).data(), k->spirv[v]) << name;
    }
  }
}

// The library's error for double precision on OpenGL ES named the command-line flags ("use --precision float
// (or auto) with --backend gles"), which a library or Python caller has not got; the tool translates it.
TEST(KernelRegistry, NoFloat64ErrorSpeaksOfDeformOptions) {
  const Error gles = noFloat64Error(device("llvmpipe", "OpenGL ES 3.2 Mesa 25.0.7", "gles"));
  EXPECT_EQ(gles.kind(), ErrorKind::Input);
  EXPECT_NE(std::string(gles.what()).find("DeformOptions::precision"), std::string::npos) << gles.what();
  EXPECT_EQ(std::string(gles.what()).find("--"), std::string::npos) << gles.what();
  const Error vulkan = noFloat64Error(device("some GPU", "1.0"));
  EXPECT_EQ(vulkan.kind(), ErrorKind::Device);
  EXPECT_EQ(std::string(vulkan.what()).find("--"), std::string::npos) << vulkan.what();
}

// A GL device without float64 is one whose doubles the GL backend refuses (NVIDIA's): the error says why
// and where doubles run instead, not that the device has none.
TEST(KernelRegistry, NoFloat64ErrorOnOpenGlSaysTheDriverRoundsDoubles) {
  const Error gl = noFloat64Error(device("NVIDIA H200/PCIe/SSE2", "4.5.0 NVIDIA 580.159.04", "gl"));
  EXPECT_EQ(gl.kind(), ErrorKind::Device);
  const std::string what = gl.what();
  EXPECT_NE(what.find("rounds the kernels' doubles to float"), std::string::npos) << what;
  EXPECT_NE(what.find("Vulkan"), std::string::npos) << what;
  EXPECT_EQ(what.find("--"), std::string::npos) << what;
}
