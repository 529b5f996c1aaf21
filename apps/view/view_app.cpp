// The viewer's App (view_app.h): GLFW callbacks turn input into Commands; execute() applies them to
// the lattice (LatticeEdit), the camera (OrbitCamera), the settings and files; each loop iteration
// re-deforms when the lattice or the settings changed (Scene) and draws one frame into a FrameTarget.
#include "apps/view/view_app.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <glad/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <sffd/error.h>
#include "model/lattice_fold.h"
#include "io/io_util.h"
#include "io/lattice_io.h"
#include "model/lattice_pack.h"
#include "apps/view/view_camera.h"
#include "apps/view/view_draw.h"
#include "apps/view/view_edit.h"
#include "apps/view/view_script.h"

namespace sffd::view {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::string upper(std::string s) {
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

struct Summary {
  double median = 0, min = 0, max = 0;
};
Summary summarize(std::vector<double> v) {
  Summary s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.min = v.front();
  s.max = v.back();
  s.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  return s;
}

class App {
 public:
  explicit App(ViewConfig& c);
  ~App();
  int run();
  void execute(const Command& c);

 private:
  enum class Mouse { None, Orbit, Pan, DragPoints, Box };
  void redeform();
  void drawFrame(bool present);
  // A gesture is in progress (a mouse button held, or a script's press before its release): frames are
  // drafts, so that dragging stays interactive on a CPU device.
  bool interacting() const { return mouse_ != Mouse::None || scriptPress_; }
  // What is drawn is not what should be: the lattice or the settings changed, or a draft outlived its gesture.
  bool stale() const {
    return deformedVersion_ != edit_.version() || settingsDirty_ || (scene_->drawingDraft() && !interacting());
  }
  void fit();
  void progress(const std::string& what);
  void status(const std::string& what, bool toStderr = true);
  std::string resolve(const std::string& path, const std::string& autoName);
  size_t pointIndex(const Command& c, size_t first) const;
  glm::dvec3 selectionCentre() const;
  void setFlag(const std::string& name, bool on);
  bool& flag(const std::string& name);
  void checkFold();
  // input
  static App* of(GLFWwindow* w) { return static_cast<App*>(glfwGetWindowUserPointer(w)); }
  static void detach(GLFWwindow* w);
  void onKey(int key, int mods);
  void onButton(int button, int action, int mods);
  void onCursor(double x, double y);
  glm::dvec2 cursorPixels(double x, double y) const;

  ViewConfig& cfg_;
  GLFWwindow* window_;
  std::unique_ptr<gl::Renderer> renderer_;
  std::unique_ptr<Overlays> overlays_;
  std::unique_ptr<Scene> scene_;
  FrameTarget target_;
  LatticeEdit edit_;
  SceneSettings settings_;
  gl::RenderOptions ro_;
  OrbitCamera camera_;
  gl::SlotCamera lastCam_;
  bool haveCam_ = false;
  int fbW_ = 0, fbH_ = 0;
  bool showEdges_ = false, showNormals_ = false, showLattice_ = true, showHud_ = true;
  size_t deformedVersion_ = size_t(-1);
  bool settingsDirty_ = true, quit_ = false, scriptPress_ = false;
  std::string foldText_, statusText_;
  Clock::time_point statusAt_{};
  int screenshotCount_ = 0;
  // timing
  double lastFrameMs_ = 0, lastDrawMs_ = 0, pendingUpdateMs_ = 0;
  bool deformedThisFrame_ = false;
  std::vector<double> frameMs_, drawMs_, deformMs_, updateMs_;   // full-quality frames that re-deformed
  std::vector<double> draftFrameMs_;                                 // draft frames that re-deformed
  // mouse
  Mouse mouse_ = Mouse::None;
  glm::dvec2 mouseAt_{0}, boxFrom_{0};
  bool boxAdd_ = false;
};

App::App(ViewConfig& c)
    : cfg_(c),
      window_(static_cast<GLFWwindow*>(c.window->nativeWindow())),
      edit_(c.lattice),
      settings_(c.settings),
      ro_(c.render) {
  if (!window_) throw Error(ErrorKind::Internal, "view: the context has no window");
  renderer_ = std::make_unique<gl::Renderer>(c.window);
  c.window->activate();
  overlays_ = std::make_unique<Overlays>();
  scene_ = std::make_unique<Scene>(*renderer_, *c.device, c.zeroCopy, c.sessionMesh, c.options, c.draftLevel);
  glfwGetFramebufferSize(window_, &fbW_, &fbH_);
  if (fbW_ <= 0 || fbH_ <= 0) fbW_ = ro_.width, fbH_ = ro_.height;
  glfwSetWindowUserPointer(window_, this);
  glfwSetFramebufferSizeCallback(window_, [](GLFWwindow* w, int width, int height) {
    of(w)->fbW_ = std::max(width, 0);
    of(w)->fbH_ = std::max(height, 0);
  });
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int mods) {
    if (action != GLFW_RELEASE) of(w)->onKey(key, mods);
  });
  glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int b, int a, int m) { of(w)->onButton(b, a, m); });
  glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) { of(w)->onCursor(x, y); });
  glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) {
    Command c{"zoom", {}, {std::pow(1.1, dy)}};
    of(w)->execute(c);
  });
  glfwSwapInterval(0);
}

void App::detach(GLFWwindow* w) {
  glfwSetFramebufferSizeCallback(w, nullptr);
  glfwSetKeyCallback(w, nullptr);
  glfwSetMouseButtonCallback(w, nullptr);
  glfwSetCursorPosCallback(w, nullptr);
  glfwSetScrollCallback(w, nullptr);
  glfwSetWindowUserPointer(w, nullptr);
}

// The window outlives the App (the context is shared): no callback may reach a destroyed App.
App::~App() {
  detach(window_);
  try {
    renderer_->context().activate();   // FrameTarget and the overlays delete their GL objects
  } catch (...) {
  }
}

// ---- frame loop ----

void App::progress(const std::string& what) {
  if (!cfg_.quiet) std::fprintf(stderr, "sffd: view: %s\n", what.c_str());
  if (fbW_ <= 0 || fbH_ <= 0) return;
  // A frame that says what is happening, so a long pre-compute does not look like a hung window.
  renderer_->context().activate();
  target_.bind(fbW_, fbH_);
  glClearColor(0.93f, 0.93f, 0.94f, 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  renderer_->drawText({upper(what), "PLEASE WAIT..."}, 8, 8, fbW_, fbH_);
  target_.resolve(true);
  glfwSwapBuffers(window_);
  glfwPollEvents();
}

void App::status(const std::string& what, bool toStderr) {
  statusText_ = what;
  statusAt_ = Clock::now();
  if (toStderr && !cfg_.quiet) std::fprintf(stderr, "sffd: view: %s\n", what.c_str());
}

void App::checkFold() {
  std::string w = foldWarning(checkLatticeFold(packLattice(edit_.lattice())), cfg_.latticeName);
  if (!w.empty() && w != foldText_) std::fprintf(stderr, "sffd: warning: %s\n", w.c_str());
  foldText_ = w;
}

void App::redeform() {
  const bool first = deformedVersion_ == size_t(-1);
  // Only a move of the lattice during a gesture is drawn as a draft: orbiting keeps the full result.
  settings_.draft = interacting() && (deformedVersion_ != edit_.version() || scene_->drawingDraft());
  try {
    scene_->update(edit_.lattice(), settings_, [this](const std::string& s) { progress(s); });
  } catch (const Error& e) {
    if (first) throw;
    // Keep the last picture; say why (a device running out of memory, a lattice the method refuses).
    status(std::string("deformation failed: ") + e.what());
  }
  if (deformedVersion_ != edit_.version()) checkFold();
  deformedVersion_ = edit_.version();
  settingsDirty_ = false;
  pendingUpdateMs_ = scene_->times().updateMs;
  deformedThisFrame_ = true;
  if (first) fit();
}

void App::fit() {
  scene_->prepareFit();
  gl::RenderOptions o = ro_;
  o.placement.reset();
  const int w = std::max(fbW_, 1), h = std::max(fbH_, 1);
  std::vector<gl::SlotCamera> cams = renderer_->cameras(o, w, h);
  if (cams.empty()) return;
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::dvec3& p : scene_->resultPoints()) lo = glm::min(lo, p), hi = glm::max(hi, p);
  for (const glm::dvec3& p : edit_.lattice().controlPoints) lo = glm::min(lo, p), hi = glm::max(hi, p);
  camera_.fitTo(cams[0], 0.5 * glm::length(hi - lo));
}

void App::drawFrame(bool present) {
  if (fbW_ <= 0 || fbH_ <= 0) return;   // minimised: nothing to draw into
  const auto t0 = Clock::now();
  renderer_->context().activate();
  camera_.apply(ro_);
  const bool draft = interacting();
  target_.bind(fbW_, fbH_, draft && scene_->draftsOn() ? 1 : 4);   // no multisampling while dragging
  std::vector<gl::SlotCamera> cams = renderer_->draw(ro_, fbW_, fbH_);
  if (!cams.empty()) lastCam_ = cams[0], haveCam_ = true;
  if (haveCam_) {
    if (showEdges_) overlays_->drawTessEdges(lastCam_, scene_->tessSources());
    if (showNormals_) overlays_->drawNormals(lastCam_, scene_->tessSources(), scene_->normalLength());
    if (showLattice_) overlays_->drawLattice(lastCam_, edit_.lattice(), edit_.selection());
  }
  if (mouse_ == Mouse::Box) overlays_->drawRect(boxFrom_.x, boxFrom_.y, mouseAt_.x, mouseAt_.y, fbW_, fbH_);
  if (showHud_) {
    const StageTimes& t = scene_->times();
    std::vector<std::string> lines = {
        "FRAME " + fmt("%.1f", lastFrameMs_) + " MS  (DRAW " + fmt("%.1f", lastDrawMs_) + ")",
        "PN " + fmt("%.2f", t.pnMs) + "  CLIP " + fmt("%.2f", t.clipMs) + "  DEFORM " + fmt("%.2f", t.deformMs) + " MS",
        upper(settings_.method + " / " + settings_.clip + " / " + scene_->path() + " / " + cfg_.backendLabel) +
            (scene_->drawingDraft() ? "  DRAFT LEVEL " + std::to_string(scene_->level()) : ""),
        std::to_string(scene_->subTriangles()) + " SUB-TRIANGLES, " + std::to_string(scene_->outputTriangles()) +
            " TRIANGLES",
        "SELECTED " + std::to_string(edit_.selection().size()) + (settings_.heatmap ? "  HEAT MAP: GEOMETRY ERROR" : ""),
    };
    int scale = renderer_->drawText(lines, 8, 8, fbW_, fbH_);
    int y = 8 + int(lines.size()) * 10 * scale + 8 * scale;
    if (!foldText_.empty()) {
      renderer_->drawText({"WARNING: THE LATTICE FOLDS OVER"}, 8, y, fbW_, fbH_, {0.8f, 0.05f, 0.05f, 1}, scale);
      y += 14 * scale;
    }
    if (!statusText_.empty() && msSince(statusAt_) < 4000)
      renderer_->drawText({upper(statusText_.substr(0, 100))}, 8, y, fbW_, fbH_, {0.1f, 0.1f, 0.12f, 1}, scale);
  }
  target_.resolve(present);
  glFinish();   // frame time includes the GPU's work (llvmpipe and lavapipe draw asynchronously too)
  lastDrawMs_ = msSince(t0);
  lastFrameMs_ = lastDrawMs_ + (deformedThisFrame_ ? pendingUpdateMs_ : 0);
  if (deformedThisFrame_ && scene_->drawingDraft()) {
    draftFrameMs_.push_back(lastFrameMs_);
  } else if (deformedThisFrame_) {
    frameMs_.push_back(lastFrameMs_);
    drawMs_.push_back(lastDrawMs_);
    deformMs_.push_back(scene_->times().deformMs);
    updateMs_.push_back(pendingUpdateMs_);
  }
  deformedThisFrame_ = false;
  if (present) glfwSwapBuffers(window_);
}

int App::run() {
  std::vector<Command> script;
  if (!cfg_.replayPath.empty()) script = readScript(cfg_.replayPath);   // every line checked before any work
  glfwSetWindowTitle(window_, ("sffd view - " + cfg_.meshName).c_str());
  size_t next = 0;
  while (!quit_) {
    if (!script.empty() || !cfg_.replayPath.empty()) {
      if (next >= script.size()) break;
      const Command& c = script[next++];
      try {
        execute(c);
      } catch (const Error& e) {
        if (e.kind() != ErrorKind::Input) throw;
        throw inputError(cfg_.replayPath, c.line, e.what());
      }
      glfwPollEvents();
    } else {
      if (glfwWindowShouldClose(window_)) break;
      const bool busy = mouse_ != Mouse::None || stale();
      if (busy) glfwPollEvents();
      else glfwWaitEventsTimeout(0.25);
    }
    if (stale()) redeform();
    drawFrame(true);
  }
  // Statistics of the frames that re-deformed (a move, a setting).
  Summary f = summarize(frameMs_), d = summarize(deformMs_), g = summarize(drawMs_), u = summarize(updateMs_);
  Summary df = summarize(draftFrameMs_);
  if (!cfg_.quiet && !frameMs_.empty())
    std::fprintf(stderr, "sffd: view: %zu frames with a deformation: median frame %.1f ms (update %.1f ms, deform stage %.2f ms, draw %.1f ms), %s path\n",
                 frameMs_.size(), f.median, u.median, d.median, g.median, scene_->path().c_str());
  if (!cfg_.quiet && !draftFrameMs_.empty())
    std::fprintf(stderr, "sffd: view: %zu draft frames while dragging (level %d, no multisampling): median frame %.1f ms\n",
                 draftFrameMs_.size(), cfg_.draftLevel, df.median);
  if (!cfg_.statsPath.empty()) {
    auto stat = [](const Summary& s) {
      return "{\"median\": " + fmt("%.3f", s.median) + ", \"min\": " + fmt("%.3f", s.min) + ", \"max\": " + fmt("%.3f", s.max) + "}";
    };
    std::ofstream out(cfg_.statsPath);
    out << "{\"mesh\": \"" << cfg_.meshName << "\", \"method\": \"" << settings_.method << "\", \"path\": \"" << scene_->path()
        << "\", \"backend\": \"" << cfg_.backendLabel << "\", \"width\": " << fbW_ << ", \"height\": " << fbH_
        << ", \"sub_triangles\": " << scene_->subTriangles() << ", \"output_triangles\": " << scene_->outputTriangles()
        << ", \"frames\": " << frameMs_.size() << ", \"frame_ms\": " << stat(f) << ", \"update_ms\": " << stat(u)
        << ", \"deform_ms\": " << stat(d) << ", \"draw_ms\": " << stat(g) << ", \"pn_ms\": " << fmt("%.3f", scene_->times().pnMs)
        << ", \"clip_ms\": " << fmt("%.3f", scene_->times().clipMs) << ", \"draft_level\": " << cfg_.draftLevel
        << ", \"draft_frames\": " << draftFrameMs_.size() << ", \"draft_frame_ms\": " << stat(df) << "}\n";
    if (!out) throw inputError(cfg_.statsPath, 0, "cannot write the statistics");
  }
  return 0;
}

// ---- commands ----

std::string App::resolve(const std::string& path, const std::string& autoName) {
  std::filesystem::path p = path == "auto" ? std::filesystem::path(autoName) : std::filesystem::path(path);
  if (p.is_relative()) p = std::filesystem::path(cfg_.outDir) / p;
  return p.string();
}

size_t App::pointIndex(const Command& c, size_t first) const {
  const Lattice& L = edit_.lattice();
  int ijk[3];
  for (int a = 0; a < 3; ++a) {
    double v = c.numbers[first + a];
    if (v < 0 || v >= L.counts[a])
      throw Error(ErrorKind::Input, c.verb + ": point index " + std::to_string(long(v)) + " is outside 0.." +
                                        std::to_string(L.counts[a] - 1) + " on axis " + "ijk"[a]);
    ijk[a] = int(v);
  }
  return L.index(ijk[0], ijk[1], ijk[2]);
}

glm::dvec3 App::selectionCentre() const {
  glm::dvec3 c(0);
  for (size_t p : edit_.selection()) c += edit_.lattice().controlPoints[p];
  return edit_.selection().empty() ? c : c / double(edit_.selection().size());
}

bool& App::flag(const std::string& name) {
  if (name == "wireframe") return ro_.wireframe;
  if (name == "edges") return showEdges_;
  if (name == "normals") return showNormals_;
  if (name == "heatmap") return settings_.heatmap;
  if (name == "lattice") return showLattice_;
  return showHud_;
}

void App::setFlag(const std::string& name, bool on) {
  bool& f = flag(name);
  if (f == on) return;
  f = on;
  if (name == "heatmap") settingsDirty_ = true;
  if (name == "normals" && on && !overlays_->normalsSupported()) status("normals: this GL has no storage buffers in vertex shaders");
}

void App::execute(const Command& c) {
  const std::string& v = c.verb;
  auto need = [&](bool ok, const std::string& what) {
    if (!ok) throw Error(ErrorKind::Input, v + ": " + what);
  };
  if (v == "drag") {
    edit_.select({pointIndex(c, 0)});
    edit_.beginGesture();
    edit_.moveSelected({c.numbers[3], c.numbers[4], c.numbers[5]});
    edit_.endGesture();
  } else if (v == "drag-screen") {
    need(haveCam_, "no frame drawn yet");
    const double x = c.numbers[0], y = c.numbers[1];
    auto hit = pickPoint(lastCam_, edit_.lattice().controlPoints, fbH_, x, y, 12);
    need(hit.has_value(), "no control point within 12 pixels of " + fmt("%g", x) + "," + fmt("%g", y));
    if (!edit_.selected(*hit)) edit_.select({*hit});
    edit_.beginGesture();
    edit_.moveSelected(pixelDeltaToWorld(lastCam_, selectionCentre(), c.numbers[2], c.numbers[3]));
    edit_.endGesture();
  } else if (v == "move") {
    need(!edit_.selection().empty(), "no point is selected");
    edit_.moveSelected({c.numbers[0], c.numbers[1], c.numbers[2]});
  } else if (v == "select") {
    if (c.words[0] == "all") edit_.selectAll();
    else if (c.words[0] == "none") edit_.clearSelection();
    else {
      std::vector<size_t> pts;
      for (size_t i = 0; i < c.numbers.size(); i += 3) pts.push_back(pointIndex(c, i));
      edit_.select(pts);
    }
  } else if (v == "select-box") {
    need(haveCam_, "no frame drawn yet");
    edit_.select(pointsInBox(lastCam_, edit_.lattice().controlPoints, fbH_, c.numbers[0], c.numbers[1], c.numbers[2], c.numbers[3]),
                 boxAdd_);
  } else if (v == "undo") {
    if (!edit_.undo()) status("nothing to undo");
  } else if (v == "redo") {
    if (!edit_.redo()) status("nothing to redo");
  } else if (v == "reset") {
    edit_.replace(edit_.original());
  } else if (v == "method" || v == "clip") {
    static const std::vector<std::string> methods = {"smooth", "accurate", "classic"}, clips = {"regular", "knot-box"};
    const auto& list = v == "method" ? methods : clips;
    std::string& cur = v == "method" ? settings_.method : settings_.clip;
    std::string want = c.words[0];
    if (want == "next") want = list[(std::find(list.begin(), list.end(), cur) - list.begin() + 1) % list.size()];
    if (want != cur) {
      cur = want;
      settingsDirty_ = true;
      status(v + " " + want, false);
    }
  } else if (v == "toggle") {
    setFlag(c.words[0], !flag(c.words[0]));
  } else if (v == "set") {
    setFlag(c.words[0], c.words[1] == "on");
  } else if (v == "view") {
    need(c.numbers[1] >= -90 && c.numbers[1] <= 90, "the elevation must be within -90..90 degrees");
    ro_.azimuthDeg = c.numbers[0];
    ro_.elevationDeg = c.numbers[1];
  } else if (v == "orbit") {
    camera_.orbit(ro_, c.numbers[0], c.numbers[1]);
  } else if (v == "pan") {
    if (haveCam_) camera_.pan(lastCam_, c.numbers[0], c.numbers[1]);
  } else if (v == "zoom") {
    camera_.zoom(c.numbers[0]);
  } else if (v == "fit") {
    if (stale()) redeform();
    fit();
  } else if (v == "resize") {
    const int w = int(c.numbers[0]), h = int(c.numbers[1]);
    if (w > 0 && h > 0) {
      glfwSetWindowSize(window_, w, h);
      glfwPollEvents();
    }
    // The picture is drawn offscreen at this size whatever the window system made of the request;
    // 0 x 0 acts as a minimised window (nothing is drawn, everything else goes on).
    fbW_ = w;
    fbH_ = h;
  } else if (v == "screenshot") {
    const std::string path = resolve(c.words[0], "sffd-view-" + std::to_string(++screenshotCount_) + ".png");
    if (io::lowerExtension(path) != ".png")   // as `sffd render` (PNG data under another name misleads)
      throw Error(ErrorKind::Input, path + ": a screenshot is a PNG picture; name it .png");
    if (fbW_ <= 0 || fbH_ <= 0) {
      std::fprintf(stderr, "sffd: warning: %s: the window has no pixels (minimised); no screenshot\n", path.c_str());
      return;
    }
    if (stale()) redeform();
    drawFrame(false);
    renderer_->context().activate();
    gl::writePng(path, target_.read());
    status("wrote " + path + " (" + settings_.method + ", " + scene_->path() + ")");
  } else if (v == "save-lattice") {
    const std::string path = resolve(c.words[0], "sffd-view-lattice.json");
    writeLattice(path, edit_.lattice());   // the format its extension names, as `sffd lattice -o`
    status("wrote " + path);
  } else if (v == "load-lattice") {
    const std::string path = resolve(c.words[0], "");
    LatticeReadOptions lo;
    lo.haveMeshBox = !cfg_.sessionMesh.positions.empty();
    lo.meshBoxLo = glm::dvec3(1e300), lo.meshBoxHi = glm::dvec3(-1e300);
    for (const auto& p : cfg_.sessionMesh.positions) lo.meshBoxLo = glm::min(lo.meshBoxLo, p), lo.meshBoxHi = glm::max(lo.meshBoxHi, p);
    edit_.replace(readLattice(path, lo));
    status("loaded " + path);
  } else if (v == "save-mesh") {
    const std::string path = resolve(c.words[0], "sffd-view-mesh.obj");
    if (stale()) redeform();
    writeMesh(path, scene_->resultMesh(), 9);
    status("wrote " + path);
  } else if (v == "key") {
    auto k = keyCommand(c.words[0]);
    need(k.has_value(), "'" + c.words[0] + "' is not a bound key");
    execute(*k);
  } else if (v == "press") {
    scriptPress_ = true;   // as a mouse button held: the frames until release are drafts
    edit_.beginGesture();
  } else if (v == "release") {
    scriptPress_ = false;
    edit_.endGesture();
  } else if (v == "quit") {
    quit_ = true;
  }
  // "frame": nothing; the loop draws a frame after every command.
}

// ---- input ----

glm::dvec2 App::cursorPixels(double x, double y) const {
  int ww = 1, wh = 1;
  glfwGetWindowSize(window_, &ww, &wh);
  return {x * fbW_ / std::max(ww, 1), y * fbH_ / std::max(wh, 1)};
}

void App::onKey(int key, int mods) {
  std::string name;
  if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) name = std::string(1, char('a' + key - GLFW_KEY_A));
  else if (key >= GLFW_KEY_F1 && key <= GLFW_KEY_F12) name = "f" + std::to_string(key - GLFW_KEY_F1 + 1);
  else if (key == GLFW_KEY_ESCAPE) name = "escape";
  else return;
  if (mods & GLFW_MOD_ALT) name = "alt+" + name;
  if (mods & GLFW_MOD_CONTROL) name = "ctrl+" + name;
  if (mods & GLFW_MOD_SHIFT) name = "shift+" + name;
  auto c = keyCommand(name);
  if (!c) return;
  try {
    execute(*c);
  } catch (const Error& e) {
    status(e.what());
  }
}

void App::onButton(int button, int action, int mods) {
  double x = 0, y = 0;
  glfwGetCursorPos(window_, &x, &y);
  const glm::dvec2 p = cursorPixels(x, y);
  if (action == GLFW_PRESS) {
    mouseAt_ = p;
    if (button == GLFW_MOUSE_BUTTON_MIDDLE || button == GLFW_MOUSE_BUTTON_RIGHT ||
        (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT) && !(mods & GLFW_MOD_CONTROL))) {
      mouse_ = Mouse::Pan;
    } else if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_CONTROL)) {
      mouse_ = Mouse::Box;
      boxFrom_ = p;
      boxAdd_ = (mods & GLFW_MOD_SHIFT) != 0;
    } else if (button == GLFW_MOUSE_BUTTON_LEFT) {
      auto hit = haveCam_ && showLattice_ ? pickPoint(lastCam_, edit_.lattice().controlPoints, fbH_, p.x, p.y, 12) : std::nullopt;
      if (hit) {
        if (!edit_.selected(*hit)) edit_.select({*hit});
        edit_.beginGesture();
        mouse_ = Mouse::DragPoints;
      } else {
        mouse_ = Mouse::Orbit;
      }
    }
  } else if (action == GLFW_RELEASE) {
    if (mouse_ == Mouse::Box) {
      try {
        execute(Command{"select-box", {}, {boxFrom_.x, boxFrom_.y, p.x, p.y}});
      } catch (const Error& e) {
        status(e.what());
      }
      boxAdd_ = false;
    }
    if (mouse_ == Mouse::DragPoints) edit_.endGesture();
    mouse_ = Mouse::None;
  }
}

void App::onCursor(double x, double y) {
  const glm::dvec2 p = cursorPixels(x, y), d = p - mouseAt_;
  try {
    switch (mouse_) {
      case Mouse::Orbit: execute(Command{"orbit", {}, {-0.4 * d.x, 0.4 * d.y}}); break;
      case Mouse::Pan: execute(Command{"pan", {}, {d.x, d.y}}); break;
      case Mouse::DragPoints:
        if (haveCam_) edit_.moveSelected(pixelDeltaToWorld(lastCam_, selectionCentre(), d.x, d.y));
        break;
      default: break;
    }
  } catch (const Error& e) {
    status(e.what());
  }
  mouseAt_ = p;
}

}  // namespace

int runViewer(ViewConfig& config) {
  App app(config);
  return app.run();
}

}  // namespace sffd::view
