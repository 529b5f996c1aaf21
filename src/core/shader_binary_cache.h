// Shader binaries a driver made, kept on disk between processes. Where a Vulkan driver of a CPU device can
// hand back what it made of a kernel's SPIR-V (VK_EXT_shader_object's binaries), a later process gives it that
// instead of the SPIR-V: lavapipe 25.0 then skips its SPIR-V to NIR translation and optimisation, about
// 70 ms of CPU a run for the four smooth kernels (docs/performance/kernels.md "Shader binaries kept on disk").
// The cache is best effort: a file that is missing, unreadable, truncated or stored under another key
// is a miss, and a failed write is forgotten; it never changes a result, only how long a build takes.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace sffd {

// The folder a device request's `shaderCache` names: "" is the default (env SFFD_SHADER_CACHE_DIR,
// else $XDG_CACHE_HOME/sffd, else $HOME/.cache/sffd; none when SFFD_SHADER_CACHE_DISABLE is set to
// anything but "" or "0", or without a home), "none" no cache, anything else that folder.
std::optional<std::filesystem::path> shaderCacheFolder(std::string_view request);
// An input Error when SFFD_SHADER_CACHE_DISABLE is set to anything but 0 or 1 (checked before any work:
// checkLibraryVariables, backend_select.h; shaderCacheFolder() would take "maybe" as 1).
void checkShaderCacheDisableVariable();

class ShaderBinaryCache {
 public:
  // The folder is made on the first store. Past `maxBytes` of binaries the least recently used go.
  explicit ShaderBinaryCache(std::filesystem::path folder, uint64_t maxBytes = uint64_t(64) << 20);

  // The binary stored under `key`, or nothing. A hit marks the file as recently used.
  std::optional<std::vector<uint8_t>> load(std::string_view key) const;
  // Writes the binary under `key` (a temporary file renamed into place, so that readers in other
  // processes see a whole file or none); false when it could not. Never throws.
  bool store(std::string_view key, std::span<const uint8_t> binary) const;

  const std::filesystem::path& folder() const { return folder_; }

  // Loads that found a binary, loads that did not, and stores, by every cache in this process.
  struct Counts {
    uint64_t hits = 0, misses = 0, stores = 0;
  };
  static Counts counts();
  // The file a key is stored in (for tests).
  std::filesystem::path fileFor(std::string_view key) const;

 private:
  std::optional<std::vector<uint8_t>> read(std::string_view key) const;
  void prune() const;

  std::filesystem::path folder_;
  uint64_t maxBytes_;
};

}  // namespace sffd
