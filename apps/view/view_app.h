// `sffd view`: the interactive viewer's window, frame loop, input and command executor. Everything
// the user can do (keys, mouse gestures, replay-script lines) runs through App::execute, so the
// replay tests cover the key bindings. apps/sffd/cmd_view.cpp loads the job, opens the window and the
// backend, and fills a ViewConfig.
#pragma once
#include <memory>
#include <string>

#include "backends/opengl/gl_context.h"
#include "apps/render/gl_renderer.h"
#include "apps/view/view_scene.h"

namespace sffd::view {

struct ViewConfig {
  std::shared_ptr<gl::Context> window;    // a visible GLFW context (gl::createGlfwContext)
  Device* device = nullptr;               // where the kernels run
  bool zeroCopy = false;                  // the device is a GL backend on `window`
  std::string backendLabel;               // for the HUD ("gl-glfw", "vulkan", "cpu")
  Mesh sessionMesh;                       // the input as loaded (after --normalize)
  DeformOptions options;                  // the job options; method and clipping come from `settings`
  Lattice lattice;
  std::string meshName, latticeName;
  gl::RenderOptions render;               // window size, view direction, up axis, wireframe
  SceneSettings settings;
  int draftLevel = 3;                     // tessellation level while dragging (no multisampling); 0: full quality
  std::string replayPath;                 // run this script, then exit
  std::string outDir = ".";               // where S, Ctrl+S, O and relative script paths write
  std::string statsPath;                  // frame-time statistics (JSON) at exit
  bool quiet = false;
};

// Runs until the window closes, `quit`, or the end of the replay script. Returns the exit status;
// throws an Error for a bad script line ("SCRIPT:LINE: what") or a failed start.
int runViewer(ViewConfig& config);

}  // namespace sffd::view
