// OpenGL 4.3+ core compute driver: implements sffd::Backend on a current GL context obtained from
// one of the context providers (gl_context.h): EGL surfaceless, OSMesa, or a GLFW window.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "backend.h"

namespace sffd::gl {

enum class Provider { Auto, EGL, OSMesa, GLFW };

struct Options {
  Provider provider = Provider::Auto;   // Auto: EGL surfaceless, then OSMesa (headless)
  std::string deviceSubstring;          // refuse a context whose GL_RENDERER does not contain it
};

// One entry per headless provider that gives a GL 4.3+ core context. Throws a device Error when none does.
std::vector<DeviceInfo> listDevices();
std::unique_ptr<Backend> createBackend(const Options& options);

}  // namespace sffd::gl
