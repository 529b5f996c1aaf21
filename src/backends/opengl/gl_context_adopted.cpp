// The application's own GL context (include/sffd/opengl.h): never made current or released by
// sffd. Whether it is still current is asked of the window system that made it, found among the
// libraries the process has loaded (GLX, EGL, OSMesa), by comparing the context handle seen at
// adoption with the current one.
#include <dlfcn.h>

#include <sffd/error.h>
#include "backends/opengl/gl_context.h"

namespace sffd::gl {

namespace {

using CurrentFn = void* (*)();

// The first "get current context" call of a loaded window-system library that names a context now.
// RTLD_NOLOAD: only libraries already in the process are looked at, none is loaded.
CurrentFn findCurrentFn() {
  static const char* const kLibraries[][2] = {
      {"libGLX.so.0", "glXGetCurrentContext"}, {"libGL.so.1", "glXGetCurrentContext"},
      {"libEGL.so.1", "eglGetCurrentContext"}, {"libOSMesa.so.8", "OSMesaGetCurrentContext"}};
  for (const auto& [library, symbol] : kLibraries) {
    void* handle = dlopen(library, RTLD_NOW | RTLD_NOLOAD);
    if (!handle) continue;
    auto fn = reinterpret_cast<CurrentFn>(dlsym(handle, symbol));
    dlclose(handle);   // drops only the reference RTLD_NOLOAD took
    if (fn && fn()) return fn;
  }
  return nullptr;
}

class AdoptedContext final : public Context {
 public:
  AdoptedContext(GLProc (*getProc)(const char*), CurrentFn current)
      : getProc_(getProc), current_(current), handle_(current ? current() : nullptr) {}
  ~AdoptedContext() override = default;   // the application's: nothing to release

  const char* name() const override { return "adopted"; }
  GLProc procAddress(const char* function) const override { return getProc_(function); }
  bool adopted() const override { return true; }

 protected:
  void makeCurrent() override {}
  void release() override {}
  // Without a window-system library to ask (another platform layer), the application's word is taken.
  bool providerCurrent() const override { return !current_ || current_() == handle_; }

 private:
  GLProc (*getProc_)(const char*);
  CurrentFn current_;
  void* handle_;
};

}  // namespace

std::unique_ptr<Context> adoptCurrentContext(GLProc (*getProc)(const char*)) {
  if (!getProc) throw deviceError("gl-adopted: adoptCurrentContext needs a GetProcAddress function");
  auto context = std::make_unique<AdoptedContext>(getProc, findCurrentFn());
  try {
    context->activate();   // glad loaded through getProc
  } catch (const Error&) {
    throw deviceError("gl-adopted: no OpenGL context is current on this thread (glad found no GL version)");
  }
  return context;
}

}  // namespace sffd::gl
