#include "core/device_timeout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <sffd/error.h>

namespace sffd {

namespace {
// The variable's seconds; 0 when it is unset or empty, -1 when it is not a number > 0.
double variableSeconds() {
  const char* s = std::getenv("SFFD_DEVICE_TIMEOUT");
  if (!s || !*s) return 0;
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  return end != s && *end == '\0' && std::isfinite(v) && v > 0 ? std::min(v, 1e9) : -1;
}
}  // namespace

double deviceTimeoutSeconds() {
  const double v = variableSeconds();
  return v > 0 ? v : 60.0;
}

void checkDeviceTimeoutVariable() {
  if (variableSeconds() < 0)
    throw Error(ErrorKind::Input, std::string("SFFD_DEVICE_TIMEOUT must be a number of seconds > 0, like 60 or 0.5, not '") +
                                      std::getenv("SFFD_DEVICE_TIMEOUT") + "'");
}

uint64_t deviceTimeoutNs() { return uint64_t(std::ceil(deviceTimeoutSeconds() * 1e9)); }

std::string deviceTimeoutMessage(const std::string& device) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g s", deviceTimeoutSeconds());
  return device + " did not finish its work within " + buf + " (SFFD_DEVICE_TIMEOUT); the driver or GPU may be hung";
}

}  // namespace sffd
