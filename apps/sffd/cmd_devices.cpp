// sffd devices: every backend and device found, one line each.
#include <cstdio>

#include "apps/sffd/cli.h"
#include <sffd/error.h>

namespace sffd::cli {
namespace {

int run(const ParsedArgs& args) {
  std::vector<std::string> problems;
  bool anyGpuApi = false;
  for (const auto& [label, info] : listDevices(&problems)) {
    if (label != "cpu") anyGpuApi = true;
    std::printf("%-10s %-40s %-10s %s%s\n", label.c_str(), info.name.c_str(), info.type.c_str(), info.driver.c_str(),
                info.limits.float64 ? " [f64]" : "");
  }
  for (const std::string& p : problems) note(args, "warning: " + p);
  if (!anyGpuApi) throw deviceError("no Vulkan or OpenGL 4.3 device found; only --backend cpu can run");
  return 0;
}

}  // namespace

CommandSpec devicesCommand() {
  return {"devices", "", "Lists the backends and devices found, one line each (backend, device, type, driver).",
          {{"--quiet", nullptr, "no notes on stderr"}, {"--help|-h", nullptr, "show this help"}}, run, 0, 0};
}

}  // namespace sffd::cli
