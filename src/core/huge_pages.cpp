#include "core/huge_pages.h"

#include <cstdint>
#include <cstdlib>
#include <fstream>

#include "core/environment_check.h"

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace sffd {

void adviseHugePages(const void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  if (!data) return;
  const uintptr_t begin = (uintptr_t(data) + kHuge - 1) & ~(kHuge - 1), end = (uintptr_t(data) + bytes) & ~(kHuge - 1);
  // Advice only: an error (an old kernel, THP off) leaves the pages as they were.
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

std::optional<std::string> tunablesForHugePages(const char* current, std::string_view thpMode) {
  if (thpMode != "madvise") return std::nullopt;   // "always": given anyway; "never": not at all
  const std::string now = current ? current : "";
  if (now.find("glibc.malloc.hugetlb") != std::string::npos) return std::nullopt;
  return now.empty() ? "glibc.malloc.hugetlb=1" : now + ":glibc.malloc.hugetlb=1";
}

// Under AddressSanitizer or ThreadSanitizer malloc is theirs, not glibc's: the tunable would change
// nothing, and a second start-up of an instrumented program costs a noticeable part of a second.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SFFD_MALLOC_IS_GLIBC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define SFFD_MALLOC_IS_GLIBC 0
#endif
#endif
#ifndef SFFD_MALLOC_IS_GLIBC
#define SFFD_MALLOC_IS_GLIBC 1
#endif

void checkHugePagesVariable() { checkVariableIsOneOf("SFFD_HUGE_PAGES", {"0", "1"}); }

void restartWithHugePages(char** argv) {
#if SFFD_MALLOC_IS_GLIBC && defined(__linux__) && defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 35)
  // Only unset, empty or 1 restarts: 0 turns it off, and anything else is refused once the tool runs
  // (checkHugePagesVariable), which a restart first would only delay.
  if (const char* v = std::getenv("SFFD_HUGE_PAGES"); v && *v && std::string_view(v) != "1") return;
  std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  std::getline(file, line);
  const size_t open = line.find('['), close = line.find(']', open);
  if (open == std::string::npos || close == std::string::npos) return;
  const char* current = std::getenv("GLIBC_TUNABLES");
  const std::optional<std::string> before = current ? std::optional<std::string>(current) : std::nullopt;
  const std::optional<std::string> tunables = tunablesForHugePages(current, line.substr(open + 1, close - open - 1));
  if (!tunables || setenv("GLIBC_TUNABLES", tunables->c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // The restart failed: go on as before.
  if (before) setenv("GLIBC_TUNABLES", before->c_str(), 1);
  else unsetenv("GLIBC_TUNABLES");
#else
  (void)argv;
#endif
}

}  // namespace sffd
