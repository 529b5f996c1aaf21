// sffd/device.h: where the kernels run. A Device is opened by name (Vulkan, OpenGL, the CPU
// reference) with the documented fallback for "auto", or adopts a device or context the application
// already owns (<sffd/vulkan.h>, <sffd/opengl.h>). Every method runs on every device: the CPU
// reference is a device like the others, and in strict mode all of them give the same bits.
//
//   sffd::Device device = sffd::Device::open({.name = "auto"});
//   std::printf("%s on %s\n", device.label().c_str(), device.info().name.c_str());
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace sffd {

class Backend;   // the internal compute interface a Device wraps

struct DeviceLimits {
  uint64_t maxStorageBufferRange = 128u << 20;   // bytes one storage binding may cover
  uint64_t storageOffsetAlignment = 256;         // alignment of a storage binding's offset
  uint32_t maxWorkGroupCount[3] = {65535, 65535, 65535};
  bool float64 = false;                          // kernels in the f64 variant can run (never on GLES, nor on NVIDIA's
                                                 // OpenGL driver, which rounds them: docs/CONFORMANCE.md)
  bool timestamps = false;                       // per-dispatch GPU times are measured
};

struct DeviceInfo {
  std::string api;       // "vulkan", "gl", "gles" (OpenGL ES 3.1) or "cpu"
  std::string provider;  // how it was reached: "vulkan", "egl", "osmesa", "glfw", "egl-es", "cpu", "adopted"
  std::string name;      // device name as the driver reports it
  std::string driver;    // driver / API version string
  std::string type;      // "discrete", "integrated", "virtual", "cpu", "other"
  // Where the API gives them (Vulkan; 0 / empty otherwise): PCI-style ids, the driver's own version
  // and the device UUID (32 hex digits), so conformance results name the exact driver.
  uint32_t vendorId = 0, deviceId = 0;
  std::string driverVersion;
  std::string uuid;
  // Vulkan on an opened device: the folder its kernels' binaries are kept in between processes (docs/CLI.md
  // "Shader cache"), where it makes them as shader objects from there; empty when it makes pipelines (every
  // other device, and listDevices(), which opens none).
  std::string shaderCache;
  DeviceLimits limits;
};

struct DeviceRequest {
  // auto (Vulkan, then GL through EGL then OSMesa, then the CPU), vulkan, gl, gl-egl, gl-osmesa,
  // gl-glfw, gles (OpenGL ES 3.1 through EGL; never picked by auto), cpu.
  std::string name = "auto";
  std::string deviceSubstring;   // the first device whose name contains it (case-insensitive)
  bool validation = false;       // Vulkan: VK_LAYER_KHRONOS_validation
  // gles: use the device's own limits. By default it holds itself to the OpenGL ES 3.1 minimum
  // limits (4 storage blocks a kernel, 16 KiB uniform blocks, 128 MiB storage ranges, 65535 groups
  // an axis) whatever the driver reports, as a minimum phone would (docs/GLES.md). SFFD_GLES_LIMITS=
  // device|minimum overrides it.
  bool deviceLimits = false;
  // Vulkan: where kernels the driver has translated are kept for later processes, on CPU devices whose
  // driver can give them back (VK_EXT_shader_object binaries; lavapipe 25 then skips its SPIR-V
  // translation, about 70 ms of a run; GPU drivers keep their own pipeline caches). "" (default): env SFFD_SHADER_CACHE_DIR, else $XDG_CACHE_HOME/sffd, else
  // ~/.cache/sffd, none when SFFD_SHADER_CACHE_DISABLE=1; "none": no cache; anything else: that folder.
  // At most 64 MiB, least recently used first out. Results are the same with or without it.
  std::string shaderCache = {};
};

// One device that can be opened here, as listDevices() reports it.
struct DeviceEntry {
  std::string label;   // the name that opens it: "vulkan", "gl-egl", "gl-osmesa", "gles", "cpu"
  DeviceInfo info;
};

class Device {
 public:
  // Opens the device asked for; throws a device Error (ErrorKind::Device) when it is unusable. For
  // "auto", devices that fail are skipped and `notes` receives one line for each. An SFFD_* variable set to
  // a value docs/CLI.md ("Environment variables") does not give it is an input Error first, here, in
  // listDevices() and in the adopting calls.
  static Device open(const DeviceRequest& request = {}, std::vector<std::string>* notes = nullptr);

  // A Device may be moved while Deformers use it: they follow it to where it was moved. A moved-from
  // Device throws an input Error from every call but destruction and assignment.

  Device(Device&&) noexcept;
  Device& operator=(Device&&) noexcept;
  ~Device();

  const std::string& label() const;   // "vulkan", "gl-egl", "gl-osmesa", "gl-glfw", "gles", "gl-adopted", "gles-adopted", "vulkan-adopted", "cpu"
  const DeviceInfo& info() const;

  // Internal: the compute backend (src/core/backend.h). Not part of the stable API.
  Backend& backend();
  explicit Device(std::string label, std::unique_ptr<Backend> backend);
  // Internal: what a Deformer holds, which moves with the Device (a Deformer made on a Device keeps working
  // after the Device is moved, into a std::vector say), and the Device that holds it now.
  struct Impl;
  Impl* handle() const;
  static Device& of(Impl* handle);

 private:
  std::unique_ptr<Impl> impl_;
  Impl& impl() const;   // an input Error on a moved-from Device
};

// Every device that can be opened here; `problems` receives one line per API that failed.
std::vector<DeviceEntry> listDevices(std::vector<std::string>* problems = nullptr);

}  // namespace sffd
