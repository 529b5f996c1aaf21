// How long a backend waits for its device before calling it hung: a hung driver must end in a device
// error (exit 3), not hang sffd forever (docs/ROBUSTNESS.md "Limits").
#pragma once
#include <cstdint>
#include <string>

namespace sffd {

// SFFD_DEVICE_TIMEOUT seconds (a number > 0; tests set tiny ones), else 60.
double deviceTimeoutSeconds();
// An input Error when SFFD_DEVICE_TIMEOUT is set to anything but such a number (checked before any work:
// checkLibraryVariables, backend_select.h; deviceTimeoutSeconds() would wait 60 s instead).
void checkDeviceTimeoutVariable();
uint64_t deviceTimeoutNs();

// "DEVICE did not finish its work within 60 s (SFFD_DEVICE_TIMEOUT); the driver or GPU may be hung".
std::string deviceTimeoutMessage(const std::string& device);

}  // namespace sffd
