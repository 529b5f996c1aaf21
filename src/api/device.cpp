// sffd::Device (<sffd/device.h>): a named or adopted compute backend behind the public API.
#include <sffd/device.h>

#include <sffd/error.h>

#include "backends/backend_select.h"
#include "core/backend.h"

namespace sffd {

struct Device::Impl {
  std::string label;
  DeviceInfo info;
  std::unique_ptr<Backend> backend;
};

Device::Device(std::string label, std::unique_ptr<Backend> backend) : impl_(std::make_unique<Impl>()) {
  impl_->label = std::move(label);
  if (backend) impl_->info = backend->info();
  impl_->backend = std::move(backend);
}

Device::Device(Device&&) noexcept = default;
Device& Device::operator=(Device&&) noexcept = default;
Device::~Device() = default;

Device Device::open(const DeviceRequest& request, std::vector<std::string>* notes) {
  BackendRequest r;
  r.name = request.name;
  r.device = request.deviceSubstring;
  r.validation = request.validation;
  r.deviceLimits = request.deviceLimits;
  r.shaderCache = request.shaderCache;
  OpenedBackend b = openBackend(r, notes);
  Device d(b.label, std::move(b.backend));
  d.impl_->info = b.info;
  return d;
}

const std::string& Device::label() const { return impl_->label; }
const DeviceInfo& Device::info() const { return impl_->info; }

Backend& Device::backend() {
  if (!impl_->backend) throw Error(ErrorKind::Internal, impl_->label + ": no compute backend behind this device");
  return *impl_->backend;
}

std::vector<DeviceEntry> listDevices(std::vector<std::string>* problems) {
  std::vector<std::string> ignored;
  std::vector<DeviceEntry> out;
  for (auto& [label, info] : listBackends(problems ? *problems : ignored)) out.push_back({label, info});
  return out;
}

}  // namespace sffd
