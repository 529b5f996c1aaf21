// End-to-end tests of `sffd render`: a deformed .bpt model to a PNG of the requested size, the
// comparison layouts, and the contract's errors (exit status, one line, no file left behind).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "apps/render/gl_renderer.h"
#include "tests/support/cli_runner.h"

namespace fs = std::filesystem;

namespace {

const std::string kData = SFFD_TEST_DATA;
const std::string kSffd = SFFD_BINARY;
const std::string kTeapot = kData + "/teapot.bpt";
const std::string kLattice = kData + "/lattices/teapot_bend.npy";

struct Result {
  int status = -1;
  std::string err;
};

Result sffd(const std::string& args, const std::string& env = "") {
  fs::path dir = fs::temp_directory_path() / ("sffd_render_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string errFile = (dir / "stderr").string();
  std::string cmd = sffd::test::bounded("LIBGL_ALWAYS_SOFTWARE=1 " + env + " " + kSffd + " " + args) + " >/dev/null 2>" + errFile;
  int raw = std::system(cmd.c_str());
  Result r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
  std::ifstream f(errFile);
  std::stringstream ss;
  ss << f.rdbuf();
  r.err = ss.str();
  return r;
}

fs::path freshDir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("sffd_render_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void expectOneErrorLine(const Result& r) {
  EXPECT_EQ(r.err.rfind("sffd: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

size_t filesIn(const fs::path& dir) {
  size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.is_regular_file();
  return n;
}

// Distinct colours, coarsely: a blank or flat picture has a handful.
size_t colourCount(const sffd::gl::Image& img) {
  std::set<uint32_t> colours;
  for (size_t i = 0; i + 3 < img.rgba.size(); i += 4)
    colours.insert((uint32_t(img.rgba[i] >> 2) << 12) | (uint32_t(img.rgba[i + 1] >> 2) << 6) | (img.rgba[i + 2] >> 2));
  return colours.size();
}

TEST(Render, DeformedTeapotToPng) {
  fs::path dir = freshDir("teapot");
  std::string out = (dir / "t.png").string();
  Result r = sffd("render " + kTeapot + " -l " + kLattice + " --method classic -o " + out + " --width 320 --height 240");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("wrote " + out), std::string::npos) << r.err;
  sffd::gl::Image img = sffd::gl::readPng(out);
  EXPECT_EQ(img.width, 320);
  EXPECT_EQ(img.height, 240);
  EXPECT_GT(colourCount(img), 50u) << "a blank picture";
  // The model is in the middle of the picture: its centre differs from the background beside it (the
  // background is a vertical gradient: the same on a row).
  int d = 0;
  for (int ch = 0; ch < 3; ++ch) d = std::max(d, std::abs(int(img.pixel(160, 120)[ch]) - int(img.pixel(1, 120)[ch])));
  EXPECT_GT(d, 10);
  EXPECT_EQ(filesIn(dir), 1u);

  // The undeformed model (no lattice) differs from the deformed one.
  std::string plain = (dir / "plain.png").string();
  r = sffd("render " + kTeapot + " -o " + plain + " --width 320 --height 240 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  sffd::gl::Image undeformed = sffd::gl::readPng(plain);
  ASSERT_EQ(undeformed.rgba.size(), img.rgba.size());
  EXPECT_NE(undeformed.rgba, img.rgba);
  fs::remove_all(dir);
}

TEST(Render, OptionsAndComparisons) {
  fs::path dir = freshDir("options");
  std::string a = (dir / "a.png").string(), b = (dir / "b.png").string(), c = (dir / "c.png").string();
  Result r = sffd("render " + kTeapot + " -l " + kLattice + " --method classic --compare classic -o " + a +
                  " --width 400 --height 160 --view 120,35 --wireframe --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  sffd::gl::Image img = sffd::gl::readPng(a);
  EXPECT_EQ(img.width, 400);
  EXPECT_EQ(img.height, 160);
  // Same method on both sides: the two halves are the same picture (captions apart).
  int worst = 0;
  for (int y = 20; y < img.height; ++y)
    for (int x = 0; x < 200; ++x)
      for (int ch = 0; ch < 3; ++ch)
        worst = std::max(worst, std::abs(int(img.pixel(x, y)[ch]) - int(img.pixel(x + 200, y)[ch])));
  EXPECT_LE(worst, 2);

  r = sffd("render " + kTeapot + " -l " + kLattice + " --method classic --compare input -o " + b +
           " --width 400 --height 160 --up y --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  r = sffd("render " + kTeapot + " -o " + c + " --view=-30,-10 --quiet --backend cpu");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(sffd::gl::readPng(c).width, 1200);   // the default size
  fs::remove_all(dir);
}

// A mesh without normals drawn alone has the creases the methods keep (--crease-angle): a cube's face is
// one flat shade (it was shaded smooth across the cube's edges, a gradient over every face).
TEST(Render, TheInputAloneKeepsItsCreases) {
  fs::path dir = freshDir("creases");
  {
    std::ofstream f(dir / "box.obj");   // no normals
    for (int i = 0; i < 8; ++i) f << "v " << (i & 1 ? 1 : -1) << ' ' << (i & 2 ? 1 : -1) << ' ' << (i & 4 ? 1 : -1) << '\n';
    f << "f 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\n";
  }
  const std::string png = (dir / "box.png").string();
  Result r = sffd("render " + (dir / "box.obj").string() + " -o " + png + " --width 300 --height 300 --view 30,20 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const sffd::gl::Image img = sffd::gl::readPng(png);
  // Two points well inside the face that looks at the viewer's left (a cube at azimuth 30 fills the middle).
  int worst = 0;
  for (int ch = 0; ch < 3; ++ch) worst = std::max(worst, std::abs(int(img.pixel(110, 130)[ch]) - int(img.pixel(140, 200)[ch])));
  EXPECT_LE(worst, 2) << "a face of the cube is not one shade";
  fs::remove_all(dir);
}

TEST(Render, BadRequestsLeaveNoFile) {
  fs::path dir = freshDir("bad");
  const std::string base = "render " + kTeapot + " -l " + kLattice + " --method classic --quiet ";
  for (const std::string& args : {
           base + "-o " + (dir / "t.jpg").string(),                       // not .png
           base + "-o " + (dir / "t").string(),                           // no extension
           base + "-o " + (dir / "missing" / "t.png").string(),           // no such folder
           base + "-o " + dir.string() + "/",                             // a folder
           base + "-o " + (dir / "t.png").string() + " --width 0",       // size
           base + "-o " + (dir / "t.png").string() + " --height 100000",
           base + "-o " + (dir / "t.png").string() + " --view 30",        // needs AZ,EL
           base + "-o " + (dir / "t.png").string() + " --view 30,95",
           base + "-o " + (dir / "t.png").string() + " --up w",
           base + "-o " + (dir / "t.png").string() + " --compare smooth",
           "render " + kTeapot + " --compare classic -o " + (dir / "t.png").string(),   // needs -l
           base + "-o " + (dir / "t.png").string() + " --method nope",
           "render " + (dir / "nothing.obj").string() + " -o " + (dir / "t.png").string(),
           "render " + kTeapot + " -l " + kLattice + " -o " + kLattice,   // an input as output
       }) {
    Result r = sffd(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    expectOneErrorLine(r);
    EXPECT_EQ(filesIn(dir), 0u) << args;
  }
  fs::remove_all(dir);
}

// No GL for pictures: a device error (exit 3), and no file. A GLFW context without a display stands for
// a machine without EGL and OSMesa.
TEST(Render, NoGlIsADeviceError) {
  fs::path dir = freshDir("nogl");
  std::string out = (dir / "t.png").string();
  Result r = sffd("render " + kTeapot + " -o " + out, "env -u DISPLAY -u WAYLAND_DISPLAY SFFD_GL_PROVIDER=glfw");
  EXPECT_EQ(r.status, 3) << r.err;
  expectOneErrorLine(r);
  EXPECT_EQ(filesIn(dir), 0u);
  fs::remove_all(dir);
}

TEST(Render, Help) {
  Result r = sffd("render --help");
  EXPECT_EQ(r.status, 0);
}

}  // namespace
