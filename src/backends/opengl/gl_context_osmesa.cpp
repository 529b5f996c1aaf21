// OSMesa context provider: Mesa's off-screen GL (always llvmpipe/softpipe), GL 4.5..4.3 core.
// libOSMesa.so.8 is opened at run time: OSMesa was removed from Mesa 25.1, so it is optional and
// never the only headless path. The header is used for types and constants only.
#include <GL/osmesa.h>

#include <string>
#include <vector>

#include <sffd/error.h>
#include "backends/opengl/gl_context.h"
#include "backends/opengl/runtime_library.h"

namespace sffd::gl {

namespace {

struct OSMesaLib : RuntimeLibrary {
  using CreateContextAttribsFn = OSMesaContext (*)(const int* attribList, OSMesaContext sharelist);
  using DestroyContextFn = void (*)(OSMesaContext ctx);
  using MakeCurrentFn = GLboolean (*)(OSMesaContext ctx, void* buffer, GLenum type, GLsizei width, GLsizei height);
  using GetCurrentContextFn = OSMesaContext (*)();
  using GetProcAddressFn = OSMESAproc (*)(const char* funcName);

  CreateContextAttribsFn CreateContextAttribs = nullptr;
  DestroyContextFn DestroyContext = nullptr;
  MakeCurrentFn MakeCurrent = nullptr;
  GetCurrentContextFn GetCurrentContext = nullptr;
  GetProcAddressFn GetProcAddress = nullptr;

  OSMesaLib() : RuntimeLibrary("libOSMesa", {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}) {
    require(CreateContextAttribs, "OSMesaCreateContextAttribs");
    require(DestroyContext, "OSMesaDestroyContext");
    require(MakeCurrent, "OSMesaMakeCurrent");
    require(GetCurrentContext, "OSMesaGetCurrentContext");
    require(GetProcAddress, "OSMesaGetProcAddress");
    finishRequired();
  }
};

OSMesaLib& lib() {
  static OSMesaLib l;
  return l;
}

class OSMesaGLContext final : public Context {
 public:
  explicit OSMesaGLContext(OSMesaContext ctx) : ctx_(ctx), color_(kSide * kSide * 4) {}
  ~OSMesaGLContext() override {
    releaseIfCurrent();
    OSMesaLib& l = lib();
    if (l.GetCurrentContext() == ctx_) l.MakeCurrent(nullptr, nullptr, 0, 0, 0);
    l.DestroyContext(ctx_);
  }
  const char* name() const override { return "osmesa"; }
  bool releasedBetweenCalls() const override { return true; }
  GLProc procAddress(const char* function) const override {
    return reinterpret_cast<GLProc>(lib().GetProcAddress(function));
  }

 protected:
  void makeCurrent() override {
    // A colour buffer must be bound even though compute never draws into it.
    if (!lib().MakeCurrent(ctx_, color_.data(), GL_UNSIGNED_BYTE, kSide, kSide))
      throw deviceError("osmesa: OSMesaMakeCurrent failed");
  }
  void release() override { lib().MakeCurrent(nullptr, nullptr, 0, 0, 0); }
  bool providerCurrent() const override { return lib().GetCurrentContext() == ctx_; }

 private:
  static constexpr int kSide = 16;
  OSMesaContext ctx_;
  std::vector<unsigned char> color_;
};

}  // namespace

std::unique_ptr<Context> createOSMesaContext() {
  OSMesaLib& l = lib();
  if (!l.ok())
    throw deviceError("osmesa: cannot load libOSMesa.so.8 (" + l.loadError +
                      "; OSMesa is gone from Mesa 25.1 on: use the egl provider)");
  OSMesaContext ctx = nullptr;
  for (int minor = 5; minor >= 3 && !ctx; --minor) {
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                           OSMESA_ACCUM_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 4, OSMESA_CONTEXT_MINOR_VERSION, minor, 0};
    ctx = l.CreateContextAttribs(attribs, nullptr);
  }
  if (!ctx) throw deviceError("osmesa: OSMesaCreateContextAttribs gave no OpenGL 4.3+ core context");
  auto context = std::make_unique<OSMesaGLContext>(ctx);
  context->activate();   // current, glad loaded
  return context;
}

}  // namespace sffd::gl
