// What the context providers share: the per-thread current context and glad loading on switch.
#include "backends/opengl/gl_context.h"

#include <dlfcn.h>

#include <atomic>
#include <cstdlib>
#include <string_view>

#include <glad/gl.h>

#include <sffd/error.h>
#include "core/environment_check.h"

namespace sffd::gl {

namespace {
// The sffd context current on this thread (activate() keeps it; providers release it on destruction).
thread_local Context* tCurrent = nullptr;
// The context whose entry points glad's (process-wide) table holds: making it current again, after
// a release at the end of a call (endCall) or on another thread, needs no reload (EGL's and the other
// providers' entry points do not depend on the context current).
std::atomic<const Context*> gGladLoadedBy{nullptr};

GLADapiproc loadThrough(void* userptr, const char* name) {
  return reinterpret_cast<GLADapiproc>(static_cast<const Context*>(userptr)->procAddress(name));
}
GLProc procThrough(void* userptr, const char* name) { return static_cast<const Context*>(userptr)->procAddress(name); }

// Whether the current context is OpenGL ES, from its version string ("OpenGL ES 3.2 Mesa 22.3.6").
bool currentIsEs(const Context& context) {
  auto getString = reinterpret_cast<const GLubyte* (*)(GLenum)>(context.procAddress("glGetString"));
  const GLubyte* version = getString ? getString(GL_VERSION) : nullptr;
  return version && std::string_view(reinterpret_cast<const char*>(version)).starts_with("OpenGL ES");
}
}  // namespace

const char* providerName(Provider provider) {
  switch (provider) {
    case Provider::Auto: return "auto";
    case Provider::EGL: return "egl";
    case Provider::OSMesa: return "osmesa";
    case Provider::GLFW: return "glfw";
    case Provider::EGLES: return "egl-es";
  }
  return "?";
}

Provider parseProvider(const std::string& name) {
  if (name == "auto") return Provider::Auto;
  if (name == "egl") return Provider::EGL;
  if (name == "osmesa") return Provider::OSMesa;
  if (name == "glfw") return Provider::GLFW;
  if (name == "egl-es") return Provider::EGLES;
  throw Error(ErrorKind::Input, "unknown GL provider '" + name + "' (egl, osmesa, glfw, egl-es)");
}

void checkGlProviderVariable() { checkVariableIsOneOf("SFFD_GL_PROVIDER", {"egl", "osmesa", "glfw"}); }

Provider providerFromEnvironment() {
  checkGlProviderVariable();
  const char* env = std::getenv("SFFD_GL_PROVIDER");
  return env && *env ? parseProvider(env) : Provider::Auto;
}

bool providerLibraryPresent(Provider provider) {
  const char* const* names = nullptr;
  static const char* const egl[] = {"libEGL.so.1", "libEGL.so", nullptr};
  static const char* const osmesa[] = {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so", nullptr};
  switch (provider) {
    case Provider::Auto: return providerLibraryPresent(Provider::EGL) || providerLibraryPresent(Provider::OSMesa);
    case Provider::GLFW: return true;   // linked in
    case Provider::EGL:
    case Provider::EGLES: names = egl; break;
    case Provider::OSMesa: names = osmesa; break;
  }
  for (const char* const* n = names; *n; ++n) {
    // The providers keep their libraries open for the life of the process, so this handle is not closed
    // either: a dlclose of Mesa is never safe.
    if (dlopen(*n, RTLD_NOW | RTLD_LOCAL)) return true;
  }
  return false;
}

Context::~Context() {
  // Derived destructors released the context already (releaseIfCurrent); forget it in any case.
  if (tCurrent == this) tCurrent = nullptr;
  const Context* self = this;   // a later context at this address loads glad again
  gGladLoadedBy.compare_exchange_strong(self, nullptr);
}

bool Context::isCurrent() const { return tCurrent == this; }

void Context::activate() {
  if (adopted()) {
    // The application's context: made current by the application only. The sffd context that was
    // current here before is left alone (the application switched away from it itself).
    if (!providerCurrent())
      throw deviceError("gl-adopted: the adopted OpenGL context is not current on this thread");
    if (tCurrent == this) return;
    tCurrent = this;
    loadGlad();
    return;
  }
  if (tCurrent == this && providerCurrent()) return;
  if (tCurrent) {
    tCurrent->release();
    tCurrent = nullptr;
  }
  makeCurrent();
  tCurrent = this;
  loadGlad();
}

void Context::loadGlad() {
  // The GL entry points belong to the provider's library (OSMesa has its own copy of Mesa's GL):
  // reload them whenever another context becomes current.
  if (gGladLoadedBy.load() == this) return;
  gGladLoadedBy = nullptr;   // being overwritten
  es_ = currentIsEs(*this);
  if (es_) {
    glVersion_ = loadGlesEntryPoints(procThrough, this);
  } else {
    int version = gladLoadGLUserPtr(loadThrough, this);
    glVersion_ = version ? GLAD_VERSION_MAJOR(version) * 10 + GLAD_VERSION_MINOR(version) : 0;
  }
  if (glVersion_ == 0) {
    release();
    tCurrent = nullptr;
    throw deviceError(std::string(name()) + ": cannot load the GL entry points (glad found no GL version)");
  }
  gGladLoadedBy = this;
}

void Context::deactivateCurrent() {
  if (tCurrent) {
    tCurrent->release();
    tCurrent = nullptr;
  }
}

void Context::endCall() noexcept {
  if (releasedBetweenCalls()) releaseIfCurrent();
}

void Context::releaseIfCurrent() {
  if (tCurrent == this) {
    release();
    tCurrent = nullptr;
  }
}

std::unique_ptr<Context> createContext(Provider provider) {
  switch (provider) {
    case Provider::EGL: return createEglContext();
    case Provider::OSMesa: return createOSMesaContext();
    case Provider::GLFW: return createGlfwContext();
    case Provider::EGLES: return createEglEsContext();
    case Provider::Auto: break;
  }
  throw Error(ErrorKind::Internal, "createContext: pick a provider (Auto is resolved by the GL driver)");
}

}  // namespace sffd::gl
