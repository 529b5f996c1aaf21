// End-to-end tests of `sffd view --replay`: a scripted session under an X server (DISPLAY, or
// xvfb-run when it is installed; skipped otherwise) whose screenshots must match `sffd render` of the
// saved lattice; undo/redo exactness, a window resized to nothing, a folding lattice, key bindings,
// and bad script lines (one error line, exit 2, checked before a window is opened).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "apps/render/gl_renderer.h"
#include "tests/support/cli_runner.h"

namespace fs = std::filesystem;

namespace {

const std::string kData = SFFD_TEST_DATA;
const std::string kSphere = kData + "/sphere.obj";

struct Result {
  int status = -1;
  std::string err;
};

using sffd::test::slurp;
fs::path freshDir(const std::string& name) { return sffd::test::tempDir("view_" + name); }

// The X server prefix: none with a DISPLAY, xvfb-run without one; nullopt when neither is there.
std::optional<std::string> xPrefix() {
  const char* d = std::getenv("DISPLAY");
  if (d && *d) return std::string();
  if (std::system("command -v xvfb-run >/dev/null 2>&1") == 0) return std::string("xvfb-run -a -s '-screen 0 1280x1024x24' ");
  return std::nullopt;
}

Result run(const std::string& args, const fs::path&, const std::string& prefix = "") {
  sffd::test::RunResult r = sffd::test::runSffd(args, "LIBGL_ALWAYS_SOFTWARE=1 " + prefix);
  return {r.status, r.err};
}


void writeFile(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// A bent identity lattice around the sphere (JSON, so render reads it with no conventions).
fs::path makeLattice(const fs::path& dir) {
  fs::path l = dir / "start.json";
  Result r = run("lattice " + kSphere + " -o " + l.string() + " --counts 4,4,4 --preset bend:0.3 --quiet", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  return l;
}

#define NEED_X(prefix)                                                              \
  auto prefix##Opt = xPrefix();                                                     \
  if (!prefix##Opt) GTEST_SKIP() << "no DISPLAY and no xvfb-run: the viewer needs an X server"; \
  const std::string prefix = *prefix##Opt

struct Diff {
  double meanAbs = 0;     // mean absolute channel difference, in 1/255
  double farShare = 0;    // share of pixels with a channel differing by more than 16
};
Diff compare(const sffd::gl::Image& a, const sffd::gl::Image& b) {
  Diff d;
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  if (a.rgba.size() != b.rgba.size() || a.rgba.empty()) return {255, 1};
  size_t far = 0, n = a.rgba.size() / 4;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    int worst = 0;
    for (int c = 0; c < 3; ++c) {
      int v = std::abs(int(a.rgba[4 * i + c]) - int(b.rgba[4 * i + c]));
      sum += v;
      worst = std::max(worst, v);
    }
    far += worst > 16;
  }
  d.meanAbs = sum / (3.0 * n);
  d.farShare = double(far) / n;
  return d;
}

// Between press and release the moves are drafts (level --draft-tess, no multisampling); release draws
// the full result, the same pixels as a session that never drafted.
TEST(View, DraftsWhileDraggingThenFullQualityOnRelease) {
  NEED_X(x);
  fs::path dir = freshDir("draft");
  fs::path lat = makeLattice(dir);
  const std::string moves = "drag 1 1 3 0 0 0.1\ndrag 1 1 3 0 0 0.1\ndrag 1 1 3 0 0 0.15\n";
  writeFile(dir / "drafts.txt", "resize 320 240\nset hud off\nset lattice off\npress\n" + moves +
                                    "screenshot during.png\nrelease\nframe\nscreenshot after.png\n");
  writeFile(dir / "plain.txt", "resize 320 240\nset hud off\nset lattice off\n" + moves + "screenshot plain.png\n");
  const std::string common = "view " + kSphere + " -l " + lat.string() + " --out-dir " + dir.string() + " --width 320 --height 240 ";
  Result r = run(common + "--replay " + (dir / "drafts.txt").string() + " --stats " + (dir / "drafts.json").string(), dir, x);
  ASSERT_EQ(r.status, 0) << r.err;
  Result p = run(common + "--replay " + (dir / "plain.txt").string() + " --stats " + (dir / "plain.json").string(), dir, x);
  ASSERT_EQ(p.status, 0) << p.err;
  const auto drafts = nlohmann::json::parse(slurp(dir / "drafts.json"));
  const auto plain = nlohmann::json::parse(slurp(dir / "plain.json"));
  EXPECT_EQ(drafts["draft_level"], 3);
  EXPECT_EQ(drafts["draft_frames"], 3) << drafts.dump();   // one a drag
  EXPECT_EQ(plain["draft_frames"], 0) << plain.dump();
  // After release the picture is the full-quality one; during the gesture it is not.
  auto after = sffd::gl::readPng((dir / "after.png").string()), full = sffd::gl::readPng((dir / "plain.png").string());
  EXPECT_EQ(after.rgba, full.rgba);
  EXPECT_GT(compare(sffd::gl::readPng((dir / "during.png").string()), full).meanAbs, 0.0);
  EXPECT_NE(run(common + "--draft-tess 65 --replay " + (dir / "plain.txt").string(), dir, x).status, 0);
  // --draft-tess 0, or a level not below --tess: full quality throughout the gesture.
  for (const char* off : {"--draft-tess 0", "--draft-tess 10 --tess 10"}) {
    Result o = run(common + off + " --replay " + (dir / "drafts.txt").string() + " --stats " + (dir / "off.json").string(), dir, x);
    ASSERT_EQ(o.status, 0) << o.err;
    EXPECT_EQ(nlohmann::json::parse(slurp(dir / "off.json"))["draft_frames"], 0) << off;
    EXPECT_EQ(sffd::gl::readPng((dir / "during.png").string()).rgba, full.rgba) << off;
  }
}

TEST(View, ReplayScreenshotsMatchRender) {
  NEED_X(x);
  fs::path dir = freshDir("match");
  fs::path lat = makeLattice(dir);
  writeFile(dir / "moves.txt",
            "resize 400 300\n"
            "set hud off\n"
            "set lattice off\n"
            "drag 1 1 3 0 0 0.35\n"
            "select 2 2 0 2 1 0\n"
            "move 0.2 0 -0.1\n"
            "select-box 0 0 400 300   # every point in the window\n"
            "select none\n"
            "fit\n"
            "screenshot smooth.png\n"
            "save-lattice moved.json\n"
            "method classic\n"
            "fit\n"
            "screenshot classic.png\n");
  Result r = run("view " + kSphere + " -l " + lat.string() + " --replay " + (dir / "moves.txt").string() + " --out-dir " +
                     dir.string() + " --width 400 --height 300",
                 dir, x);
  ASSERT_EQ(r.status, 0) << r.err;
  // Smooth on the window's GL context is drawn where the kernels wrote it.
  EXPECT_NE(r.err.find("smooth.png (smooth, zero-copy)"), std::string::npos) << r.err;
  for (std::string method : {"smooth", "classic"}) {
    fs::path ref = dir / ("render_" + method + ".png");
    Result rr = run("render " + kSphere + " -l " + (dir / "moved.json").string() + " --method " + method +
                        " --width 400 --height 300 --quiet -o " + ref.string(),
                    dir);
    ASSERT_EQ(rr.status, 0) << rr.err;
    Diff d = compare(sffd::gl::readPng((dir / (method + ".png")).string()), sffd::gl::readPng(ref.string()));
    std::printf("view %s against render: mean abs diff %.3f/255, %.4f%% of pixels off by more than 16\n", method.c_str(),
                d.meanAbs, 100 * d.farShare);
    EXPECT_LT(d.meanAbs, 2.0) << method;
    EXPECT_LT(d.farShare, 0.01) << method;
  }
  // The moves changed the picture: the screenshot differs from a render of the starting lattice.
  fs::path start = dir / "render_start.png";
  ASSERT_EQ(run("render " + kSphere + " -l " + lat.string() + " --width 400 --height 300 --quiet -o " + start.string(), dir).status, 0);
  EXPECT_GT(compare(sffd::gl::readPng((dir / "smooth.png").string()), sffd::gl::readPng(start.string())).farShare, 0.02);
}

// A model far from the origin, or 1e-30 or 1e30 across, is drawn straight from the Deformer's buffers too
// (they hold its local frame: the renderer and the overlays take Deformer::localOrigin() and
// localScale()); it was drawn from a download every frame. The pictures are those of the model at size 1.
TEST(View, FarAndOddSizedModelsAreDrawnInPlace) {
  NEED_X(x);
  fs::path dir = freshDir("frames");
  std::ofstream far(dir / "far.obj");
  far.precision(17);
  for (std::istringstream in(slurp(kSphere)); in;) {
    std::string line;
    std::getline(in, line);
    double p[3];
    if (std::sscanf(line.c_str(), "v %lf %lf %lf", &p[0], &p[1], &p[2]) == 3) far << "v " << p[0] + 1e6 << " " << p[1] - 1e6 << " " << p[2] + 1e6 << "\n";
    else far << line << "\n";
  }
  far.close();
  writeFile(dir / "shots.txt", "resize 320 240\nset hud off\nset lattice off\nset edges on\nset normals on\nfit\nscreenshot shot.png\n");
  auto shoot = [&](const std::string& mesh, const std::string& normalize) {
    const fs::path lattice = dir / "l.json";
    EXPECT_EQ(run("lattice " + mesh + normalize + " -o " + lattice.string() + " --preset twist:0.4 --quiet", dir).status, 0);
    Result r = run("view " + mesh + normalize + " -l " + lattice.string() + " --tess 3 --replay " + (dir / "shots.txt").string() +
                       " --out-dir " + dir.string() + " --width 320 --height 240",
                   dir, x);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("shot.png (smooth, zero-copy)"), std::string::npos) << mesh << normalize << "\n" << r.err;
    return sffd::gl::readPng((dir / "shot.png").string());
  };
  const sffd::gl::Image unit = shoot(kSphere, "");
  for (const auto& [mesh, normalize] : {std::pair<std::string, std::string>{(dir / "far.obj").string(), ""},
                                        {kSphere, " --normalize 1e-30"},
                                        {kSphere, " --normalize 1e30"}}) {
    const Diff d = compare(shoot(mesh, normalize), unit);
    EXPECT_LT(d.meanAbs, 1.0) << mesh << normalize;
    EXPECT_LT(d.farShare, 0.005) << mesh << normalize;
  }
}

TEST(View, UndoRedoRestoreTheLatticeExactly) {
  NEED_X(x);
  fs::path dir = freshDir("undo");
  fs::path lat = makeLattice(dir);
  writeFile(dir / "undo.txt",
            "save-lattice l0.json\n"
            "drag 1 2 3 0.1 0.2 0.3\n"
            "select all\n"
            "move 0.013 -0.7 1e-3\n"
            "key ctrl+z\n"
            "drag 0 0 0 -0.3 0 0\n"
            "save-lattice l2.json\n"
            "undo\n"
            "undo\n"
            "save-lattice u.json\n"
            "redo\n"
            "key ctrl+y\n"
            "save-lattice r.json\n"
            "undo\nundo\nundo\nundo   # more than there is: a note, not an error\n"
            "save-lattice u2.json\n");
  Result r = run("view " + kSphere + " -l " + lat.string() + " --replay " + (dir / "undo.txt").string() + " --out-dir " +
                     dir.string() + " --width 200 --height 150 --method classic",
                 dir, x);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir / "u.json"), slurp(dir / "l0.json"));
  EXPECT_EQ(slurp(dir / "u2.json"), slurp(dir / "l0.json"));
  EXPECT_EQ(slurp(dir / "r.json"), slurp(dir / "l2.json"));
  EXPECT_NE(slurp(dir / "l2.json"), slurp(dir / "l0.json"));
}

TEST(View, ResizeToZeroAndFoldingLatticeKeepRunning) {
  NEED_X(x);
  fs::path dir = freshDir("bad_events");
  fs::path lat = makeLattice(dir);
  writeFile(dir / "bad.txt",
            "resize 0 0\n"
            "drag 1 1 1 0 0 0.1\n"
            "screenshot none.png   # no pixels: a warning\n"
            "resize 240 180\n"
            "drag 1 1 1 3 3 3      # folds the lattice over\n"
            "toggle heatmap\n"
            "method accurate\n"
            "clip knot-box\n"
            "method smooth\n"
            "key w\nkey e\nkey n\nkey m\nkey c\nkey f\n"
            "screenshot folded.png\n"
            "save-mesh folded.obj\n");
  Result r = run("view " + kSphere + " -l " + lat.string() + " --replay " + (dir / "bad.txt").string() + " --out-dir " +
                     dir.string() + " --width 320 --height 240 --edge-length 0.4 --tess 4",
                 dir, x);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir / "none.png"));
  EXPECT_NE(r.err.find("no pixels"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("sffd: warning: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("folds"), std::string::npos) << r.err;
  sffd::gl::Image img = sffd::gl::readPng((dir / "folded.png").string());
  EXPECT_EQ(img.width, 240);
  EXPECT_EQ(img.height, 180);
  EXPECT_GT(fs::file_size(dir / "folded.obj"), 1000u);
}

TEST(View, BadScriptLinesAreOneLineErrors) {
  // Checked before a window is opened: no X server needed.
  fs::path dir = freshDir("bad_script");
  const std::pair<std::string, std::string> cases[] = {
      {"undo\n\ndrag 1 2\n", ":3: usage: drag"},
      {"# c\nfrobnicate 1\n", ":2: unknown command 'frobnicate'"},
      {"zoom -1\n", ":1: zoom: the factor must be positive"},
      {"toggle everything\n", ":1: usage: toggle"},
      {"move 1 nan 0\n", ":1: move: 'nan' is not a finite number"},
      {"key x\n", ":1: key: 'x' is not a bound key"},
  };
  for (const auto& [text, what] : cases) {
    writeFile(dir / "s.txt", text);
    Result r = run("view " + kSphere + " --replay " + (dir / "s.txt").string(), dir);
    EXPECT_EQ(r.status, 2) << text << r.err;
    EXPECT_EQ(r.err.rfind("sffd: error: " + (dir / "s.txt").string() + what, 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  Result missing = run("view " + kSphere + " --replay " + (dir / "nope.txt").string(), dir);
  EXPECT_EQ(missing.status, 2) << missing.err;
}

TEST(View, ScriptErrorsFoundWhileRunningNameTheirLine) {
  NEED_X(x);
  fs::path dir = freshDir("run_error");
  writeFile(dir / "s.txt", "frame\ndrag 9 0 0 1 0 0\n");
  Result r = run("view " + kSphere + " --replay " + (dir / "s.txt").string() + " --width 160 --height 120 --method classic", dir, x);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("sffd: error: " + (dir / "s.txt").string() + ":2: drag: point index 9 is outside 0..4"), std::string::npos)
      << r.err;
  // A lattice is saved in the format its name says (JSON went into a .npy that nothing could read back), and
  // a screenshot under another name than .png is refused (PNG data went into x.jpg).
  writeFile(dir / "save.txt", "save-lattice " + (dir / "l.npy").string() + "\nscreenshot " + (dir / "x.jpg").string() + "\n");
  r = run("view " + kSphere + " --replay " + (dir / "save.txt").string() + " --width 160 --height 120 --method classic", dir, x);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(":2: " + (dir / "x.jpg").string() + ": a screenshot is a PNG picture; name it .png"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "x.jpg"));
  Result back = run("deform " + kSphere + " -l " + (dir / "l.npy").string() + " --method classic --quiet -o " + (dir / "o.obj").string(), dir, x);
  EXPECT_EQ(back.status, 0) << back.err;
}

}  // namespace
