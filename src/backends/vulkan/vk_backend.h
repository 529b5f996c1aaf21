// Vulkan compute driver: implements sffd::Backend on any Vulkan 1.1+ device (lavapipe included).
// The loader is opened at run time, so a machine without Vulkan gets a device Error, not a crash.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/backend.h"

namespace sffd::vk {

struct Options {
  std::string deviceSubstring = {};   // picks the first device whose name contains it (case-insensitive)
  bool validation = false;       // VK_LAYER_KHRONOS_validation; also on when SFFD_VK_VALIDATION=1
  std::string shaderCache = {};  // "" the default folder, "none", or a folder (core/shader_binary_cache.h)
};

// Every physical device, best first (discrete, integrated, virtual, CPU). Throws a device Error when
// the loader or any ICD is missing.
std::vector<DeviceInfo> listDevices();
std::unique_ptr<Backend> createBackend(const Options& options);
// Warnings and errors the validation layer reported so far in this process (tests require 0).
size_t validationMessageCount();
// Device memory allocations (vkAllocateMemory) sffd made so far in this process: tests check that a warm
// edit makes none (a discrete GPU's driver takes a fraction of a millisecond for each).
size_t deviceMemoryAllocations();

}  // namespace sffd::vk
