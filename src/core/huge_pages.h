// Transparent huge pages for large host arrays. On a machine where the kernel hands out huge pages
// only when asked (THP "madvise") every first touch of a 4 KiB page is a fault, and on a virtual
// machine a costly one: a result of a few hundred MiB spent a third of its time in them. Asking for
// huge pages on a large, freshly reserved array turns 512 of those faults into one.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sffd {

// Asks the kernel for huge pages on the whole 2 MiB pages inside [data, data + bytes) (madvise
// MADV_HUGEPAGE; a range without one is left alone). A no-op where the system has no such advice.
void adviseHugePages(const void* data, size_t bytes);

// Reserves room for `count` elements in `v` and advises huge pages on the reserved storage.
template <class T>
void reserveHuge(std::vector<T>& v, size_t count) {
  v.reserve(count);
  adviseHugePages(v.data(), v.capacity() * sizeof(T));
}

// resize(count, value) of a vector in huge pages (reserveHuge first).
template <class T>
void resizeHuge(std::vector<T>& v, size_t count, const T& value = T()) {
  reserveHuge(v, count);
  v.resize(count, value);
}

// Frees a vector's storage (`v = {}` does not: it assigns an empty initializer list, keeping the capacity).
template <class T>
void freeStorage(std::vector<T>& v) {
  std::vector<T>().swap(v);
}

// The GLIBC_TUNABLES value under which glibc's malloc (2.35 on) asks for huge pages itself, for every
// large allocation of the process, the driver's included: `current` with glibc.malloc.hugetlb=1 added.
// None where it would change nothing: the kernel's THP mode (the bracketed word of
// /sys/kernel/mm/transparent_hugepage/enabled) is not "madvise", or `current` already sets the tunable
// (the caller's choice, or a restart's).
std::optional<std::string> tunablesForHugePages(const char* current, std::string_view thpMode);

// Starts the program again (execv of /proc/self/exe, same arguments, same process id) with
// tunablesForHugePages() in its environment: a tunable is read only at start-up. Returns, and the
// program goes on as it is, where that does not apply (not Linux with glibc 2.35 or later, a sanitizer's
// malloc, nothing to change, SFFD_HUGE_PAGES set to anything but 1) or the restart fails. For a program's
// main(), before anything else.
void restartWithHugePages(char** argv);
// An input Error when SFFD_HUGE_PAGES is set to anything but 0 (no restart) or 1 (the restart, as when
// unset): the tool checks it before a command runs, where the value was taken as 1 before.
void checkHugePagesVariable();

}  // namespace sffd
