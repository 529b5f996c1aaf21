// OpenGL context providers, kept apart from the compute driver (gl_backend.cpp) in the way Filament
// separates its Platform from its Driver: a provider makes a GL 4.3+ core context current and hands
// out its entry points; the driver only ever talks to GL through glad.
//
//   egl     EGL surfaceless (libEGL.so.1, opened at run time): the durable headless path
//   egl-es  the same with an OpenGL ES 3.1 context (the gles backend, docs/GLES.md)
//   osmesa  Mesa's off-screen library (libOSMesa.so.8, opened at run time; removed in Mesa 25.1)
//   glfw    a GLFW window (hidden for compute, visible for the viewer); needs an X display
//
// No provider links a GL library: EGL and OSMesa are opened with dlopen, so a machine without them
// gets a device Error (include/sffd/error.h) when the provider is asked for, not a failure at start-up.
#pragma once
#include <memory>
#include <string>

namespace sffd::gl {

enum class Provider { Auto, EGL, OSMesa, GLFW, EGLES };

// "egl", "osmesa", "glfw", "egl-es" ("auto" for Auto).
const char* providerName(Provider provider);
// Parses a provider name as SFFD_GL_PROVIDER and the command line spell it; throws an input Error otherwise.
Provider parseProvider(const std::string& name);
// Whether the provider's library can be opened (EGL, OSMesa) or linked in (GLFW) on this machine.
// A present library may still give no context (no X display, no 4.3 core support).
bool providerLibraryPresent(Provider provider);
// What Auto becomes under SFFD_GL_PROVIDER=egl|osmesa|glfw (Auto when unset or empty); an input Error
// (checkGlProviderVariable's) for any other value.
Provider providerFromEnvironment();
void checkGlProviderVariable();

using GLProc = void (*)();

// One GL context of one provider. Not thread-safe: used by one thread at a time; a context that is
// released between calls (releasedBetweenCalls) by any thread, the others only where they are current.
class Context {
 public:
  Context() = default;
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  virtual ~Context();

  // The provider's name: "egl", "osmesa" or "glfw".
  virtual const char* name() const = 0;
  // Entry point of a GL function for this context (valid while it is current).
  virtual GLProc procAddress(const char* function) const = 0;
  // The GLFWwindow* of a glfw context (nullptr for the others).
  virtual void* nativeWindow() const { return nullptr; }

  // Makes this context current on the calling thread, releasing the sffd context that was current
  // there, and (re)loads glad's GL entry points through this provider; nothing to do when it already is.
  // Several contexts, even of different providers, may live in one process: every user of a context
  // calls activate() before its GL calls. Throws a device Error when the context cannot be made current.
  // Code outside sffd that switches contexts by itself should call deactivateCurrent() first.
  void activate();
  // Releases whichever sffd context is current on the calling thread.
  static void deactivateCurrent();
  // Whether the context is let go at the end of every call of the public API (endCall): sffd's own
  // headless contexts (EGL, OSMesa), so that their Device may be used from any thread, one at a time
  // (EGL refuses to make a context current on a thread while another still has it). Not the GLFW
  // window's, which the viewer draws with between calls, nor an adopted one.
  virtual bool releasedBetweenCalls() const { return false; }
  // The end of a public call (Backend::endCall): releases this context from the calling thread when
  // it is releasedBetweenCalls() and current here. Never throws.
  void endCall() noexcept;
  bool isCurrent() const;
  // The GL version glad found at the last activate(): major * 10 + minor (45 for 4.5, 32 for ES 3.2).
  int glVersion() const { return glVersion_; }
  // Whether the context is OpenGL ES (its GL_VERSION begins "OpenGL ES"); glad then loads the ES 3.1
  // entry points into the same table (cmake/Glad.cmake).
  bool es() const { return es_; }
  // An application's context (adoptCurrentContext): activate() never switches to it or away from
  // it, only checks that it is current here (a device Error otherwise) and loads glad through it.
  virtual bool adopted() const { return false; }

 protected:
  // Provider primitives used by activate(): make current / make nothing current on this thread, and
  // whether the provider still has this context current here (code outside sffd, such as a viewer
  // calling glfwMakeContextCurrent, may have changed it).
  virtual void makeCurrent() = 0;
  virtual void release() = 0;
  virtual bool providerCurrent() const = 0;
  // Called first by every derived destructor: releases the context if it is current on this thread.
  void releaseIfCurrent();

 private:
  void loadGlad();
  int glVersion_ = 0;
  bool es_ = false;
};

// Each throws a device Error naming the provider and the reason when no GL 4.3+ core context can be made
// (library missing, no display, version too old). The context is current when they return.
std::unique_ptr<Context> createEglContext();
std::unique_ptr<Context> createOSMesaContext();
// An OpenGL ES 3.1 context (a later compatible version where the driver gives one) through EGL.
std::unique_ptr<Context> createEglEsContext();

// Loads the OpenGL ES 3.1 entry points of the current ES context into glad's table (gl_loader_es.cpp);
// returns major * 10 + minor of the context's ES version, 0 when none could be read.
int loadGlesEntryPoints(GLProc (*load)(void* user, const char* name), void* user);

struct GlfwWindowOptions {
  bool visible = false;
  int width = 64;
  int height = 64;
  std::string title = "sffd";
};
std::unique_ptr<Context> createGlfwContext(const GlfwWindowOptions& options = {});

// The context current on this thread, owned by the application, its entry points from `getProc`.
// Throws a device Error when no context is current. (gl_context_adopted.cpp)
std::unique_ptr<Context> adoptCurrentContext(GLProc (*getProc)(const char*));

// The context of an explicit provider (Auto is refused: the driver walks the list itself).
std::unique_ptr<Context> createContext(Provider provider);

}  // namespace sffd::gl
