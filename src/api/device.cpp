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
  Device* self = nullptr;   // the Device that holds this now: moves update it, so Deformers follow their Device
};

Device::Device(std::string label, std::unique_ptr<Backend> backend) : impl_(std::make_unique<Impl>()) {
  impl_->label = std::move(label);
  if (backend) impl_->info = backend->info();
  // Opening made a GL context current on this thread: let it go, so that any thread may make the first call.
  if (backend) backend->endCall();
  impl_->backend = std::move(backend);
  impl_->self = this;
}

Device::Device(Device&& other) noexcept : impl_(std::move(other.impl_)) {
  if (impl_) impl_->self = this;
}
Device& Device::operator=(Device&& other) noexcept {
  impl_ = std::move(other.impl_);
  if (impl_) impl_->self = this;
  return *this;
}
Device::~Device() = default;

Device::Impl& Device::impl() const {
  if (!impl_) throw Error(ErrorKind::Input, "this sffd::Device was moved from; use the Device it was moved to");
  return *impl_;
}
Device::Impl* Device::handle() const { return &impl(); }
Device& Device::of(Impl* handle) { return *handle->self; }

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

const std::string& Device::label() const { return impl().label; }
const DeviceInfo& Device::info() const { return impl().info; }

Backend& Device::backend() {
  Impl& I = impl();
  if (!I.backend) throw Error(ErrorKind::Internal, I.label + ": no compute backend behind this device");
  return *I.backend;
}

std::vector<DeviceEntry> listDevices(std::vector<std::string>* problems) {
  std::vector<std::string> ignored;
  std::vector<DeviceEntry> out;
  for (auto& [label, info] : listBackends(problems ? *problems : ignored)) out.push_back({label, info});
  return out;
}

}  // namespace sffd
