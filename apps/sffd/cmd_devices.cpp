// sffd devices: every backend and device found, one line each, or as JSON with the ids, the driver
// version and the UUID where the API gives them (conformance reports name the exact driver).
#include <cstdio>

#include <nlohmann/json.hpp>

#include "apps/sffd/cli.h"
#include "apps/sffd/conform.h"
#include <sffd/error.h>

namespace sffd::cli {
namespace {

int run(const ParsedArgs& args) {
  std::vector<std::string> problems;
  bool anyGpuApi = false;
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const auto& [label, info] : listDevices(&problems)) {
    if (label != "cpu") anyGpuApi = true;
    if (args.has("--json"))
      list.push_back(nlohmann::ordered_json::parse(conform::deviceJson(label, info)));
    else
      std::printf("%-10s %-40s %-10s %s%s\n", label.c_str(), info.name.c_str(), info.type.c_str(), info.driver.c_str(),
                  info.limits.float64 ? " [f64]" : "");
  }
  if (args.has("--json")) std::printf("%s\n", nlohmann::ordered_json{{"devices", list}, {"problems", problems}}.dump(1).c_str());
  for (const std::string& p : problems) note(args, "warning: " + p);
  if (!anyGpuApi) throw deviceError("no Vulkan or OpenGL 4.3 device found; only --backend cpu can run");
  return 0;
}

}  // namespace

CommandSpec devicesCommand() {
  return {"devices", "[--json]", "Lists the backends and devices found, one line each (backend, device, type, driver).",
          {{"--json", nullptr, "print JSON: per device its backend, ids, driver version and UUID where the API gives them"},
           {"--quiet", nullptr, "no notes on stderr"},
           {"--help|-h", nullptr, "show this help"}},
          run, 0, 0};
}

}  // namespace sffd::cli
