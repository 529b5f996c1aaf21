// EGL context providers: a GL 4.3+ core context (egl) or an OpenGL ES 3.1+ context (egl-es, the gles
// backend) with no surface, on Mesa's surfaceless platform (EGL_MESA_platform_surfaceless), else on
// each EGL device (EGL_EXT_platform_device, e.g. NVIDIA). The two differ only in the client API bound
// (eglBindAPI) and the attributes asked for. libEGL.so.1 is opened at run time; the EGL headers are
// used for types and constants only.
#define EGL_NO_X11 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <dlfcn.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <sffd/error.h>
#include "backends/opengl/gl_context.h"
#include "backends/opengl/runtime_library.h"

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

namespace sffd::gl {

namespace {

struct EglLib : RuntimeLibrary {
  PFNEGLGETPROCADDRESSPROC GetProcAddress = nullptr;
  PFNEGLGETERRORPROC GetError = nullptr;
  PFNEGLQUERYSTRINGPROC QueryString = nullptr;
  PFNEGLINITIALIZEPROC Initialize = nullptr;
  PFNEGLTERMINATEPROC Terminate = nullptr;
  PFNEGLBINDAPIPROC BindAPI = nullptr;
  PFNEGLCHOOSECONFIGPROC ChooseConfig = nullptr;
  PFNEGLCREATECONTEXTPROC CreateContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC DestroyContext = nullptr;
  PFNEGLMAKECURRENTPROC MakeCurrent = nullptr;
  PFNEGLGETCURRENTCONTEXTPROC GetCurrentContext = nullptr;
  PFNEGLRELEASETHREADPROC ReleaseThread = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT = nullptr;   // EGL_EXT_platform_base
  PFNEGLGETPLATFORMDISPLAYPROC GetPlatformDisplay = nullptr;         // EGL 1.5 core
  PFNEGLQUERYDEVICESEXTPROC QueryDevicesEXT = nullptr;

  EglLib() : RuntimeLibrary("libEGL", {"libEGL.so.1", "libEGL.so"}) {
    require(GetProcAddress, "eglGetProcAddress");
    require(GetError, "eglGetError");
    require(QueryString, "eglQueryString");
    require(Initialize, "eglInitialize");
    require(Terminate, "eglTerminate");
    require(BindAPI, "eglBindAPI");
    require(ChooseConfig, "eglChooseConfig");
    require(CreateContext, "eglCreateContext");
    require(DestroyContext, "eglDestroyContext");
    require(MakeCurrent, "eglMakeCurrent");
    require(GetCurrentContext, "eglGetCurrentContext");
    require(ReleaseThread, "eglReleaseThread");
    if (!finishRequired()) return;
    GetPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYPROC>(dlsym(handle, "eglGetPlatformDisplay"));
    GetPlatformDisplayEXT =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(GetProcAddress("eglGetPlatformDisplayEXT"));
    QueryDevicesEXT = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(GetProcAddress("eglQueryDevicesEXT"));
  }
};

EglLib& lib() {
  static EglLib l;
  return l;
}

std::string errorName(EGLint e) {
  switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    default: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "EGL error 0x%04x", static_cast<unsigned>(e));
      return buf;
    }
  }
}
std::string lastError() { return errorName(lib().GetError()); }

bool hasExtension(const char* list, const std::string& ext) {
  if (!list) return false;
  std::string s = std::string(" ") + list + " ";
  return s.find(" " + ext + " ") != std::string::npos;
}

// eglInitialize / eglTerminate counted per display: EGL returns one EGLDisplay per platform and
// native display, so contexts of one display must not terminate it under each other.
std::map<EGLDisplay, int>& displayUsers() {
  static auto* m = new std::map<EGLDisplay, int>;   // never destroyed: contexts may outlive static destructors
  return *m;
}
void unrefDisplay(EGLDisplay dpy) {
  auto& users = displayUsers();
  auto it = users.find(dpy);
  if (it == users.end()) return;
  if (--it->second == 0) {
    users.erase(it);
    lib().Terminate(dpy);
  }
}

// Which client API a context speaks: eglBindAPI is per thread, so every EGL call that depends on it
// binds it first.
struct EglApi {
  bool es = false;
  EGLenum api() const { return es ? EGL_OPENGL_ES_API : EGL_OPENGL_API; }
  const char* provider() const { return es ? "egl-es" : "egl"; }
  const char* wants() const { return es ? "OpenGL ES 3.1+ context" : "OpenGL 4.3+ core context"; }
};

class EglContext final : public Context {
 public:
  EglContext(EGLDisplay dpy, EGLContext ctx, EglApi api) : dpy_(dpy), ctx_(ctx), api_(api) {}
  ~EglContext() override {
    releaseIfCurrent();
    EglLib& l = lib();
    if (l.GetCurrentContext() == ctx_) {
      l.BindAPI(api_.api());
      l.MakeCurrent(dpy_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    l.DestroyContext(dpy_, ctx_);
    unrefDisplay(dpy_);
    if (displayUsers().empty()) l.ReleaseThread();
  }
  const char* name() const override { return api_.provider(); }
  bool releasedBetweenCalls() const override { return true; }
  GLProc procAddress(const char* function) const override {
    return reinterpret_cast<GLProc>(lib().GetProcAddress(function));
  }

 protected:
  void makeCurrent() override {
    EglLib& l = lib();
    l.BindAPI(api_.api());
    if (!l.MakeCurrent(dpy_, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx_)) {
      const EGLint error = l.GetError();
      // sffd lets the context go at the end of each call (endCall), so another thread holds it only while
      // it is inside a call on the same Device (EGL lets no thread take it until that one lets go): say
      // so, rather than the bare EGL_BAD_ACCESS.
      if (error == EGL_BAD_ACCESS)
        throw deviceError(std::string(api_.provider()) + ": the device's GL context is current on another thread; use a "
                                                         "Device from one thread at a time (or open one on each thread)");
      throw deviceError(std::string(api_.provider()) + ": eglMakeCurrent failed (" + errorName(error) + ")");
    }
  }
  bool providerCurrent() const override {
    lib().BindAPI(api_.api());   // eglGetCurrentContext answers for the bound API
    return lib().GetCurrentContext() == ctx_;
  }
  void release() override {
    EglLib& l = lib();
    l.BindAPI(api_.api());
    l.MakeCurrent(dpy_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }

 private:
  EGLDisplay dpy_;
  EGLContext ctx_;
  EglApi api_;
};

// A 4.5..4.3 core context (or an ES 3.1 one) on an initialised display, or EGL_NO_CONTEXT with the reason.
EGLContext createOn(EGLDisplay dpy, EglApi api, std::string& why) {
  EglLib& l = lib();
  const char* ext = l.QueryString(dpy, EGL_EXTENSIONS);
  if (!hasExtension(ext, "EGL_KHR_surfaceless_context")) {
    why = "no EGL_KHR_surfaceless_context";
    return EGL_NO_CONTEXT;
  }
  const char* apis = l.QueryString(dpy, EGL_CLIENT_APIS);
  if (apis && !hasExtension(apis, api.es ? "OpenGL_ES" : "OpenGL")) {
    why = std::string("the display offers only ") + apis;
    return EGL_NO_CONTEXT;
  }
  if (!l.BindAPI(api.api())) {
    why = std::string("eglBindAPI(") + (api.es ? "EGL_OPENGL_ES_API" : "EGL_OPENGL_API") + ") failed (" + lastError() + ")";
    return EGL_NO_CONTEXT;
  }
  EGLConfig config = nullptr;   // EGL_NO_CONFIG_KHR
  if (!hasExtension(ext, "EGL_KHR_no_config_context") && !hasExtension(ext, "EGL_MESA_configless_context")) {
    const EGLint want[] = {EGL_RENDERABLE_TYPE, api.es ? EGL_OPENGL_ES3_BIT : EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0,
                           EGL_NONE};
    EGLint n = 0;
    if (!l.ChooseConfig(dpy, want, &config, 1, &n) || n < 1) {
      why = std::string("no EGL config renders ") + (api.es ? "OpenGL ES 3" : "OpenGL") + " (" + lastError() + ")";
      return EGL_NO_CONTEXT;
    }
  }
  if (api.es) {
    // ES 3.1 exactly is asked for; a driver may hand out a later, compatible version (Mesa: 3.2), and
    // the gles backend uses nothing past 3.1 either way.
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 1, EGL_NONE};
    EGLContext ctx = l.CreateContext(dpy, config, EGL_NO_CONTEXT, attribs);
    if (ctx == EGL_NO_CONTEXT) why = "no OpenGL ES 3.1 context (" + lastError() + ")";
    return ctx;
  }
  for (int minor = 5; minor >= 3; --minor) {
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, minor,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = l.CreateContext(dpy, config, EGL_NO_CONTEXT, attribs);
    if (ctx != EGL_NO_CONTEXT) return ctx;
    why = "no OpenGL 4.3+ core context (" + lastError() + ")";
  }
  return EGL_NO_CONTEXT;
}

// Initialises the display and makes a context on it; EGL_NO_CONTEXT (display released) on failure.
std::unique_ptr<Context> tryDisplay(EGLDisplay dpy, EglApi api, const std::string& what, std::string& reasons) {
  EglLib& l = lib();
  auto fail = [&](const std::string& why) {
    reasons += (reasons.empty() ? "" : "; ") + what + ": " + why;
    return nullptr;
  };
  if (dpy == EGL_NO_DISPLAY) return fail("no display (" + lastError() + ")");
  EGLint major = 0, minor = 0;
  if (!l.Initialize(dpy, &major, &minor)) return fail("eglInitialize failed (" + lastError() + ")");
  ++displayUsers()[dpy];
  std::string why;
  EGLContext ctx = createOn(dpy, api, why);
  if (ctx == EGL_NO_CONTEXT) {
    unrefDisplay(dpy);
    return fail(why);
  }
  return std::make_unique<EglContext>(dpy, ctx, api);
}

std::unique_ptr<Context> createEglContextOf(EglApi api) {
  EglLib& l = lib();
  if (!l.ok()) throw deviceError(std::string(api.provider()) + ": cannot load libEGL.so.1 (" + l.loadError + ")");
  const char* clientExt = l.QueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto platformDisplay = [&](EGLenum platform, void* native) -> EGLDisplay {
    if (l.GetPlatformDisplay) return l.GetPlatformDisplay(platform, native, nullptr);
    if (l.GetPlatformDisplayEXT) return l.GetPlatformDisplayEXT(platform, native, nullptr);
    return EGL_NO_DISPLAY;
  };
  std::string reasons;
  auto finish = [&](std::unique_ptr<Context> ctx) -> std::unique_ptr<Context> {
    ctx->activate();   // current, glad loaded
    return ctx;
  };

  if (hasExtension(clientExt, "EGL_MESA_platform_surfaceless")) {
    if (auto ctx = tryDisplay(platformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY), api, "surfaceless",
                              reasons))
      return finish(std::move(ctx));
  } else {
    reasons = "surfaceless: no EGL_MESA_platform_surfaceless";
  }
  if (hasExtension(clientExt, "EGL_EXT_platform_device") && l.QueryDevicesEXT) {
    EGLint n = 0;
    if (l.QueryDevicesEXT(0, nullptr, &n) && n > 0) {
      std::vector<EGLDeviceEXT> devices(static_cast<size_t>(n));
      l.QueryDevicesEXT(n, devices.data(), &n);
      for (EGLint i = 0; i < n; ++i) {
        if (auto ctx = tryDisplay(platformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[static_cast<size_t>(i)]), api,
                                  "device " + std::to_string(i), reasons))
          return finish(std::move(ctx));
      }
    }
  }
  throw deviceError(std::string(api.provider()) + ": no " + api.wants() + " without a surface (" + reasons + ")");
}

}  // namespace

std::unique_ptr<Context> createEglContext() { return createEglContextOf({.es = false}); }
std::unique_ptr<Context> createEglEsContext() { return createEglContextOf({.es = true}); }

}  // namespace sffd::gl
