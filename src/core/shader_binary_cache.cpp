#include "core/shader_binary_cache.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "core/environment_check.h"
#include "core/fnv1a.h"

namespace sffd {

namespace fs = std::filesystem;

namespace {

// A file: this magic, the key's length (u32) and bytes, the binary's length and FNV-1a (u64 each), the binary.
constexpr char kMagic[8] = {'S', 'F', 'F', 'D', 'S', 'B', '1', '\n'};
constexpr const char* kSuffix = ".bin";

std::atomic<uint64_t> gHits{0}, gMisses{0}, gStores{0};

bool envSet(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::string_view(v) != "0";
}

template <class T>
void put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

template <class T>
bool take(std::string_view& in, T& value) {
  if (in.size() < sizeof value) return false;
  std::memcpy(&value, in.data(), sizeof value);
  in.remove_prefix(sizeof value);
  return true;
}

}  // namespace

void checkShaderCacheDisableVariable() { checkVariableIsOneOf("SFFD_SHADER_CACHE_DISABLE", {"0", "1"}); }

std::optional<fs::path> shaderCacheFolder(std::string_view request) {
  if (request == "none") return std::nullopt;
  if (!request.empty()) return fs::path(request);
  if (envSet("SFFD_SHADER_CACHE_DISABLE")) return std::nullopt;
  if (const char* d = std::getenv("SFFD_SHADER_CACHE_DIR"); d && *d) return fs::path(d);
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x && x[0] == '/') return fs::path(x) / "sffd";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "sffd";
  return std::nullopt;
}

ShaderBinaryCache::ShaderBinaryCache(fs::path folder, uint64_t maxBytes) : folder_(std::move(folder)), maxBytes_(maxBytes) {}

fs::path ShaderBinaryCache::fileFor(std::string_view key) const {
  char name[32];
  std::snprintf(name, sizeof name, "%016llx%s", (unsigned long long)fnv1a64(key.data(), key.size()), kSuffix);
  return folder_ / name;
}

ShaderBinaryCache::Counts ShaderBinaryCache::counts() { return {gHits.load(), gMisses.load(), gStores.load()}; }

std::optional<std::vector<uint8_t>> ShaderBinaryCache::load(std::string_view key) const {
  std::optional<std::vector<uint8_t>> binary = read(key);
  ++(binary ? gHits : gMisses);
  return binary;
}

std::optional<std::vector<uint8_t>> ShaderBinaryCache::read(std::string_view key) const {
  const fs::path file = fileFor(key);
  std::error_code ec;
  const uintmax_t size = fs::file_size(file, ec);
  if (ec || size > maxBytes_) return std::nullopt;
  std::string bytes(size_t(size), '\0');
  {
    std::ifstream in(file, std::ios::binary);
    if (!in.read(bytes.data(), std::streamsize(bytes.size()))) return std::nullopt;
  }
  std::string_view in = bytes;
  uint32_t keyBytes = 0;
  uint64_t binaryBytes = 0, hash = 0;
  if (in.substr(0, sizeof kMagic) != std::string_view(kMagic, sizeof kMagic)) return std::nullopt;
  in.remove_prefix(sizeof kMagic);
  if (!take(in, keyBytes) || in.substr(0, keyBytes) != key) return std::nullopt;   // another key with the same name
  in.remove_prefix(keyBytes);
  if (!take(in, binaryBytes) || !take(in, hash) || in.size() != binaryBytes) return std::nullopt;
  if (fnv1a64(in.data(), in.size()) != hash) return std::nullopt;
  fs::last_write_time(file, fs::file_time_type::clock::now(), ec);   // recently used: pruned last
  return std::vector<uint8_t>(in.begin(), in.end());
}

bool ShaderBinaryCache::store(std::string_view key, std::span<const uint8_t> binary) const {
  static std::atomic<unsigned> serial{0};
  try {
    std::error_code ec;
    fs::create_directories(folder_, ec);
    if (ec) return false;
    std::string out(kMagic, sizeof kMagic);
    put(out, uint32_t(key.size()));
    out.append(key);
    put(out, uint64_t(binary.size()));
    put(out, fnv1a64(binary.data(), binary.size()));
    out.append(reinterpret_cast<const char*>(binary.data()), binary.size());
    const fs::path file = fileFor(key);
    // A name no other process or thread writes: this one's pid and a serial number.
    fs::path tmp = file;
    tmp += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(serial++);
    {
      std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
      f.write(out.data(), std::streamsize(out.size()));
      f.close();
      if (!f) {
        fs::remove(tmp, ec);
        return false;
      }
    }
    fs::rename(tmp, file, ec);
    if (ec) {
      fs::remove(tmp, ec);
      return false;
    }
    ++gStores;
    prune();
    return true;
  } catch (...) {   // std::bad_alloc, a path that cannot be formed: the cache is only ever a shortcut
    return false;
  }
}

void ShaderBinaryCache::prune() const {
  struct Entry {
    fs::path path;
    fs::file_time_type used;
    uintmax_t bytes;
  };
  std::vector<Entry> entries;
  uintmax_t total = 0;
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(folder_, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path& p = it->path();
    const std::string name = p.filename().string();
    std::error_code e;
    const fs::file_time_type used = fs::last_write_time(p, e);
    if (e) continue;
    if (name.find(".tmp") != std::string::npos) {   // left by a process that died while writing
      if (now - used > std::chrono::hours(1)) fs::remove(p, e);
      continue;
    }
    if (p.extension() != kSuffix) continue;
    const uintmax_t bytes = fs::file_size(p, e);
    if (e) continue;
    entries.push_back({p, used, bytes});
    total += bytes;
  }
  if (total <= maxBytes_) return;
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.used < b.used; });
  for (const Entry& e : entries) {
    if (total <= maxBytes_) break;
    std::error_code r;
    if (fs::remove(e.path, r)) total -= e.bytes;
  }
}

}  // namespace sffd
