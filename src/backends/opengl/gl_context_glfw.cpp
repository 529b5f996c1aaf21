// GLFW context provider: a window (hidden for compute, visible for the interactive viewer) with a
// GL 4.5..4.3 core context. Needs a display: with none, a device Error says so.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <string>

#include <sffd/error.h>
#include "backends/opengl/gl_context.h"

namespace sffd::gl {

namespace {

// glfwInit / glfwTerminate counted over the live windows of this module.
int gGlfwUsers = 0;

std::string glfwReason() {
  const char* what = nullptr;
  int code = glfwGetError(&what);
  if (code == GLFW_NO_ERROR) return "no reason given";
  return what ? what : "GLFW error " + std::to_string(code);
}

void glfwUnref() {
  if (gGlfwUsers > 0 && --gGlfwUsers == 0) glfwTerminate();
}

class GlfwContext final : public Context {
 public:
  explicit GlfwContext(GLFWwindow* window) : window_(window) {}
  ~GlfwContext() override {
    releaseIfCurrent();
    if (glfwGetCurrentContext() == window_) glfwMakeContextCurrent(nullptr);
    glfwDestroyWindow(window_);
    glfwUnref();
  }
  const char* name() const override { return "glfw"; }
  GLProc procAddress(const char* function) const override { return glfwGetProcAddress(function); }
  void* nativeWindow() const override { return window_; }

 protected:
  void makeCurrent() override {
    glfwMakeContextCurrent(window_);
    if (glfwGetCurrentContext() != window_) throw deviceError("glfw: cannot make the window's context current (" + glfwReason() + ")");
  }
  void release() override { glfwMakeContextCurrent(nullptr); }
  bool providerCurrent() const override { return glfwGetCurrentContext() == window_; }

 private:
  GLFWwindow* window_;
};

}  // namespace

std::unique_ptr<Context> createGlfwContext(const GlfwWindowOptions& options) {
  if (gGlfwUsers == 0 && !glfwInit())
    throw deviceError("glfw: cannot initialise (" + glfwReason() +
                      "); a window needs an X display (run under xvfb-run), or use the egl provider");
  ++gGlfwUsers;
  GLFWwindow* window = nullptr;
  std::string why;
  for (int minor = 5; minor >= 3 && !window; --minor) {
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, minor);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
    window = glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr);
    if (!window) why = glfwReason();
  }
  if (!window) {
    glfwUnref();
    throw deviceError("glfw: no window with an OpenGL 4.3+ core context (" + why + ")");
  }
  auto context = std::make_unique<GlfwContext>(window);
  context->activate();   // current, glad loaded
  return context;
}

}  // namespace sffd::gl
