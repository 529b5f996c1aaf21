// The check the tool makes of an environment variable that takes a few words: a value it would otherwise take
// silently as its default is refused before a command runs (docs/CLI.md).
#pragma once
#include <cstdlib>
#include <initializer_list>
#include <string>
#include <string_view>

#include <sffd/error.h>

namespace sffd {

// An input Error "NAME must be a or b, not 'v'" when NAME is set to a non-empty value not among `values`.
inline void checkVariableIsOneOf(const char* name, std::initializer_list<std::string_view> values) {
  const char* v = std::getenv(name);
  if (!v || !*v) return;
  std::string said;
  for (std::string_view w : values) {
    if (w == v) return;
    said += (said.empty() ? "" : " or ") + std::string(w);
  }
  throw Error(ErrorKind::Input, std::string(name) + " must be " + said + ", not '" + v + "'");
}

}  // namespace sffd
