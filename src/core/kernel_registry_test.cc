#include "core/kernel_registry.h"

#include <gtest/gtest.h>

using namespace sffd;

namespace {
DeviceInfo device(const char* name, const char* driver) {
  DeviceInfo d;
  d.name = name;
  d.driver = driver;
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
