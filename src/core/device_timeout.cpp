#include "core/device_timeout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sffd {

double deviceTimeoutSeconds() {
  if (const char* s = std::getenv("SFFD_DEVICE_TIMEOUT"); s && *s) {
    char* end = nullptr;
    double v = std::strtod(s, &end);
    if (end != s && *end == '\0' && std::isfinite(v) && v > 0) return std::min(v, 1e9);
  }
  return 60.0;
}

uint64_t deviceTimeoutNs() { return uint64_t(std::ceil(deviceTimeoutSeconds() * 1e9)); }

std::string deviceTimeoutMessage(const std::string& device) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g s", deviceTimeoutSeconds());
  return device + " did not finish its work within " + buf + " (SFFD_DEVICE_TIMEOUT); the driver or GPU may be hung";
}

}  // namespace sffd
