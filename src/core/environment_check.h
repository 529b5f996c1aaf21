// The checks the library and the tool make of an environment variable that takes a few words or an integer in a
// range: a value they would otherwise take silently as a default is refused before any work (docs/CLI.md
// "Environment variables").
#pragma once
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <string>
#include <string_view>

#include <sffd/error.h>

namespace sffd {

// An input Error "NAME must be a, b or c, not 'v'" when NAME is set to a non-empty value not among `values`.
inline void checkVariableIsOneOf(const char* name, std::initializer_list<std::string_view> values) {
  const char* v = std::getenv(name);
  if (!v || !*v) return;
  std::string said;
  size_t left = values.size();
  for (std::string_view w : values) {
    if (w == v) return;
    said += std::string(w) + (--left > 1 ? ", " : left == 1 ? " or " : "");
  }
  throw Error(ErrorKind::Input, std::string(name) + " must be " + said + ", not '" + v + "'");
}

// NAME's value when it is an integer lo..hi (lo >= 1, decimal digits only); 0 when NAME is unset, empty or
// anything else (which checkVariableIsInteger refuses before a reader gets to it).
inline uint64_t integerVariable(const char* name, uint64_t lo, uint64_t hi) {
  const char* v = std::getenv(name);
  if (!v || !*v) return 0;
  uint64_t n = 0;
  const char* end = v + std::strlen(v);
  const auto [p, ec] = std::from_chars(v, end, n);
  return ec == std::errc() && p == end && n >= lo && n <= hi ? n : 0;
}

// An input Error "NAME must be an integer lo..hi, not 'v'" when NAME is set to a non-empty value that is not.
inline void checkVariableIsInteger(const char* name, uint64_t lo, uint64_t hi) {
  const char* v = std::getenv(name);
  if (v && *v && !integerVariable(name, lo, hi))
    throw Error(ErrorKind::Input, std::string(name) + " must be an integer " + std::to_string(lo) + ".." + std::to_string(hi) +
                                      ", not '" + v + "'");
}

}  // namespace sffd
