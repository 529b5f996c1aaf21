// Tests of the offscreen renderer on Mesa's llvmpipe: a sphere made here is drawn small and the picture
// is checked against what the camera says it must be (silhouette area, shading, colours), the PNG
// writer is read back, and EGL and OSMesa are compared pixel by pixel.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <sffd/error.h>
#include "backends/opengl/gl_context.h"
#include "apps/render/gl_renderer.h"

namespace sffd::gl {
namespace {

namespace fs = std::filesystem;

// Software devices only, as ctest runs them (set before any GL library is opened).
const bool kSoftwareOnly = [] {
  setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
  return true;
}();

#define SKIP_WITHOUT_LIBRARY(provider)                                              \
  do {                                                                              \
    if (!providerLibraryPresent(provider))                                          \
      GTEST_SKIP() << providerName(provider) << " library not installed";           \
  } while (0)

// A UV sphere of radius r about `centre` with exact normals, counter-clockwise seen from outside.
Mesh makeSphere(double r = 1.0, glm::dvec3 centre = glm::dvec3(0), int slices = 96, int stacks = 48) {
  Mesh m;
  for (int i = 0; i <= stacks; ++i) {
    double theta = std::numbers::pi * i / stacks;   // from +z down
    for (int j = 0; j <= slices; ++j) {
      double phi = 2 * std::numbers::pi * j / slices;
      glm::dvec3 n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      m.positions.push_back(centre + r * n);
      m.normals.push_back(n);
    }
  }
  auto at = [&](int i, int j) { return static_cast<uint32_t>(i * (slices + 1) + j); };
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      if (i > 0) m.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i < stacks - 1) m.triangles.push_back({at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
    }
  weldPositions(m);
  return m;
}

double luminance(const Image& img, int x, int y) {
  const uint8_t* p = img.pixel(x, y);
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

int maxChannelDiff(const Image& a, const Image& b, int x, int y) {
  int d = 0;
  for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a.pixel(x, y)[c]) - int(b.pixel(x, y)[c])));
  return d;
}

// Pixels that differ from the background picture by more than a few levels.
double coveredFraction(const Image& img, const Image& background) {
  size_t covered = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) covered += maxChannelDiff(img, background, x, y) > 6;
  return double(covered) / (double(img.width) * img.height);
}

RenderOptions smallOptions() {
  RenderOptions o;
  o.width = 160;
  o.height = 120;
  return o;
}

struct Projected {
  double cx, cy, rx, ry;   // the sphere's silhouette in pixels (from the top left)
};
// The silhouette of a sphere (centre, radius) seen by the slot camera: a circle of angular radius
// asin(r / distance), an ellipse in pixels when the pixel aspect is not square (it is square here).
Projected silhouette(const SlotCamera& cam, glm::dvec3 centre, double r, int imageHeight) {
  glm::dvec4 clip = cam.projection * cam.view * glm::dvec4(centre, 1.0);
  glm::dvec2 ndc(clip.x / clip.w, clip.y / clip.w);
  double dist = glm::length(cam.eye - centre);
  double tanAlpha = std::tan(std::asin(r / dist));
  double tanY = std::tan(glm::radians(cam.fovYDeg) / 2);
  Projected p;
  p.cx = cam.x + (ndc.x * 0.5 + 0.5) * cam.width;
  p.cy = imageHeight - (cam.y + (ndc.y * 0.5 + 0.5) * cam.height);
  p.ry = tanAlpha / tanY * cam.height / 2;
  p.rx = tanAlpha / (tanY * cam.aspect) * cam.width / 2;
  return p;
}

class RendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SKIP_WITHOUT_LIBRARY(Provider::EGL);
    try {
      renderer = Renderer::createHeadless(Provider::EGL);
    } catch (const Error& e) {
      GTEST_SKIP() << "no EGL context here: " << e.what();
    }
  }
  std::unique_ptr<Renderer> renderer;
};

TEST_F(RendererTest, SphereSilhouetteCoversTheExpectedFraction) {
  Mesh sphere = makeSphere();
  RenderOptions o = smallOptions();
  Image background = renderer->render({}, o);
  Image img = renderer->render({{&sphere, {}, ""}}, o);
  ASSERT_EQ(img.width, 160);
  ASSERT_EQ(img.height, 120);
  ASSERT_EQ(img.rgba.size(), 160u * 120u * 4u);
  ASSERT_EQ(img.cameras.size(), 1u);

  double fraction = coveredFraction(img, background);
  EXPECT_GT(fraction, 0.05) << "blank picture";
  Projected s = silhouette(img.cameras[0], glm::dvec3(0), 1.0, img.height);
  double expected = std::numbers::pi * s.rx * s.ry / (img.width * img.height);
  EXPECT_NEAR(fraction, expected, 0.03 * expected) << "expected " << expected << ", got " << fraction;
  // The camera is fitted: the sphere spans about `fill` of the picture's smaller side.
  EXPECT_NEAR(2 * s.ry / img.height, o.fill, 0.02);
  EXPECT_NEAR(s.cx, img.width / 2.0, 1.0);
  EXPECT_NEAR(s.cy, img.height / 2.0, 1.0);
  std::printf("sphere covers %.4f of the picture, expected %.4f\n", fraction, expected);
}

// A scene of any size gives the picture of size 1: positions become float relative to the scene's centre
// and scaled by a power of two to a size of 1 to 2 (the shaders' squared lengths left float's range: a
// sphere 1e-30 across was framed off centre, its highlights lost, as one 1e30 across far from the origin).
TEST_F(RendererTest, EverySizeAndPlaceGivesThePictureOfSizeOne) {
  const RenderOptions o = smallOptions();
  const Mesh unit = makeSphere();
  const Image reference = renderer->render({{&unit, {}, ""}}, o);
  for (double size : {1e-30, 1e-12, 1e12, 1e30})
    for (double away : {0.0, 1e3}) {
      const Mesh sphere = makeSphere(size, glm::dvec3(away * size, -away * size, 0.5 * away * size));
      const Image img = renderer->render({{&sphere, {}, ""}}, o);
      ASSERT_EQ(img.rgba.size(), reference.rgba.size());
      size_t differ = 0;
      for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) differ += maxChannelDiff(img, reference, x, y) > 8;
      EXPECT_LT(differ, 20u) << size << " at " << away;
      EXPECT_NEAR(img.cameras[0].target.x / size, away, 1e-3 + 1e-9 * away) << size;
    }
}

TEST_F(RendererTest, BackgroundIsALightGradient) {
  Image bg = renderer->render({}, smallOptions());
  double top = luminance(bg, 80, 2), bottom = luminance(bg, 80, 117);
  EXPECT_GT(top, bottom + 20);
  EXPECT_GT(bottom, 170);
  RenderOptions flat = smallOptions();
  flat.gradientBackground = false;
  Image f = renderer->render({}, flat);
  EXPECT_EQ(luminance(f, 80, 2), luminance(f, 80, 117));
}

TEST_F(RendererTest, CentreIsBrighterThanTheRim) {
  Mesh sphere = makeSphere();
  Image img = renderer->render({{&sphere, {}, ""}}, smallOptions());
  Projected s = silhouette(img.cameras[0], glm::dvec3(0), 1.0, img.height);
  double centre = luminance(img, int(std::lround(s.cx)), int(std::lround(s.cy)));
  // Mean over a ring just inside the silhouette: normals there are nearly perpendicular to the view.
  double ring = 0;
  const int samples = 72;
  for (int k = 0; k < samples; ++k) {
    double a = 2 * std::numbers::pi * k / samples;
    ring += luminance(img, int(std::lround(s.cx + 0.93 * s.rx * std::cos(a))), int(std::lround(s.cy + 0.93 * s.ry * std::sin(a))));
  }
  ring /= samples;
  EXPECT_GT(centre, ring + 25) << "centre " << centre << ", rim " << ring;
  EXPECT_GT(centre, 120) << "the lit centre is dark";
  // Two-sided: the same sphere with its triangles turned inside out (normals too) looks the same.
  Mesh flipped = sphere;
  for (auto& t : flipped.triangles) std::swap(t[1], t[2]);
  for (auto& n : flipped.normals) n = -n;
  Image flippedImg = renderer->render({{&flipped, {}, ""}}, smallOptions());
  int worst = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) worst = std::max(worst, maxChannelDiff(img, flippedImg, x, y));
  EXPECT_LE(worst, 2);
}

TEST_F(RendererTest, ScalarsAreColouredWithViridis) {
  Mesh sphere = makeSphere();
  std::vector<float> height;
  for (const auto& p : sphere.positions) height.push_back(float(p.z));
  RenderOptions o = smallOptions();
  o.elevationDeg = 0;   // the poles at the top and bottom of the picture
  o.legend = false;
  Image plain = renderer->render({{&sphere, {}, ""}}, o);
  Image coloured = renderer->render({{&sphere, height, ""}}, o);
  Projected s = silhouette(coloured.cameras[0], glm::dvec3(0), 1.0, coloured.height);
  int x = int(std::lround(s.cx));
  const uint8_t* top = coloured.pixel(x, int(std::lround(s.cy - 0.7 * s.ry)));
  const uint8_t* bottom = coloured.pixel(x, int(std::lround(s.cy + 0.7 * s.ry)));
  const uint8_t* grey = plain.pixel(x, int(std::lround(s.cy - 0.7 * s.ry)));
  // High values are yellow-green (red and green above blue), low values purple-blue (blue above green).
  EXPECT_GT(top[1], top[2] + 30) << int(top[0]) << "," << int(top[1]) << "," << int(top[2]);
  EXPECT_GT(bottom[2], bottom[1] + 10) << int(bottom[0]) << "," << int(bottom[1]) << "," << int(bottom[2]);
  // Without scalars the material is nearly grey.
  EXPECT_LT(std::abs(int(grey[0]) - int(grey[2])), 20);

  // The legend takes a strip at the right with the colormap's ends.
  o.legend = true;
  Image withLegend = renderer->render({{&sphere, height, ""}}, o);
  bool sawYellow = false, sawPurple = false;
  for (int y = 0; y < withLegend.height; ++y)
    for (int xx = withLegend.width * 3 / 4; xx < withLegend.width; ++xx) {
      const uint8_t* p = withLegend.pixel(xx, y);
      sawYellow |= p[0] > 200 && p[1] > 180 && p[2] < 90;
      sawPurple |= p[2] > 70 && p[0] > 50 && p[1] < 40;
    }
  EXPECT_TRUE(sawYellow);
  EXPECT_TRUE(sawPurple);
}

TEST(Viridis, Ends) {
  glm::vec3 lo = viridis(0), hi = viridis(1), mid = viridis(0.5f);
  EXPECT_NEAR(lo.r, 0.267, 0.02);
  EXPECT_NEAR(lo.b, 0.329, 0.02);
  EXPECT_NEAR(hi.r, 0.993, 0.02);
  EXPECT_NEAR(hi.g, 0.906, 0.02);
  EXPECT_NEAR(mid.g, 0.565, 0.02);   // #21918c
  EXPECT_EQ(viridis(-3), lo);
  EXPECT_EQ(viridis(7), hi);
}

// Both ends of a legend in one format (render --color-by geometry drew 0.00807 above 4.11E-13).
TEST(LegendLabels, BothEndsInOneFormat) {
  using Labels = std::array<std::string, 2>;
  EXPECT_EQ(legendLabels(4.11e-13f, 0.00807f), (Labels{"0.00000", "0.00807"}));
  EXPECT_EQ(legendLabels(0.0f, 0.133f), (Labels{"0.000", "0.133"}));
  EXPECT_EQ(legendLabels(0.5f, 12.5f), (Labels{"0.5", "12.5"}));
  EXPECT_EQ(legendLabels(0.0f, 175.0f), (Labels{"0", "175"}));
  EXPECT_EQ(legendLabels(0.0f, 0.0f), (Labels{"0", "0"}));
  EXPECT_EQ(legendLabels(4.11e-13f, 8.07e-6f), (Labels{"4.11e-13", "8.07e-06"}));
  EXPECT_EQ(legendLabels(2.0f, 123456.0f), (Labels{"2.00e+00", "1.23e+05"}));
}

TEST_F(RendererTest, WireframeDarkensTheEdges) {
  Mesh sphere = makeSphere(1.0, glm::dvec3(0), 24, 12);
  RenderOptions o = smallOptions();
  Image shaded = renderer->render({{&sphere, {}, ""}}, o);
  o.wireframe = true;
  Image wire = renderer->render({{&sphere, {}, ""}}, o);
  double a = 0, b = 0;
  for (int y = 0; y < shaded.height; ++y)
    for (int x = 0; x < shaded.width; ++x) a += luminance(shaded, x, y), b += luminance(wire, x, y);
  EXPECT_LT(b, a * 0.97);
}

TEST_F(RendererTest, SideBySideWithCaptions) {
  Mesh left = makeSphere(1.0), right = makeSphere(0.5, glm::dvec3(5, 0, 0));
  RenderOptions o;
  o.width = 320;
  o.height = 120;
  Image bg = renderer->render({}, o);
  Image img = renderer->render({{&left, {}, "before"}, {&right, {}, "after"}}, o);
  ASSERT_EQ(img.cameras.size(), 2u);
  EXPECT_EQ(img.cameras[0].x, 0);
  EXPECT_EQ(img.cameras[1].x, 160);
  // One camera for both: the small sphere is drawn at half the size of the big one.
  Projected a = silhouette(img.cameras[0], glm::dvec3(0), 1.0, img.height);
  Projected b = silhouette(img.cameras[1], glm::dvec3(5, 0, 0), 0.5, img.height);
  EXPECT_NEAR(b.ry / a.ry, 0.5, 0.05);
  EXPECT_NEAR(a.cx, 80, 40);
  EXPECT_NEAR(b.cx, 240, 40);
  for (const Projected& p : {a, b}) {
    int x = int(std::lround(p.cx)), y = int(std::lround(p.cy));
    EXPECT_GT(maxChannelDiff(img, bg, x, y), 6) << "nothing drawn at " << x << "," << y;
  }
  // Captions: dark pixels in the band at the top of each slot.
  auto darkInBand = [&](int x0, int x1) {
    int n = 0;
    for (int y = 0; y < 12; ++y)
      for (int x = x0; x < x1; ++x) n += luminance(img, x, y) < 110;
    return n;
  };
  EXPECT_GT(darkInBand(40, 120), 10);
  EXPECT_GT(darkInBand(200, 280), 10);
  // Separate cameras: each fills its own slot.
  o.shareCamera = false;
  Image own = renderer->render({{&left, {}, ""}, {&right, {}, ""}}, o);
  Projected a2 = silhouette(own.cameras[0], glm::dvec3(0), 1.0, own.height);
  Projected b2 = silhouette(own.cameras[1], glm::dvec3(5, 0, 0), 0.5, own.height);
  EXPECT_NEAR(b2.ry / a2.ry, 1.0, 0.02);
}

TEST_F(RendererTest, RefusesBadItemsAndSizes) {
  Mesh sphere = makeSphere(1.0, glm::dvec3(0), 8, 4);
  std::vector<float> wrong(3, 0.0f);
  try {
    renderer->setItems({{&sphere, wrong, ""}});
    FAIL() << "a wrong scalar count was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
  }
  Mesh broken = sphere;
  broken.triangles[0][1] = 1u << 30;
  EXPECT_THROW(renderer->setItems({{&broken, {}, ""}}), Error);
  RenderOptions o = smallOptions();
  o.width = 0;
  try {
    renderer->render({{&sphere, {}, ""}}, o);
    FAIL() << "width 0 was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
  }
  o.width = renderer->maxSize() + 1;
  EXPECT_THROW(renderer->render(o), Error);
  // Still usable afterwards, at another size (the offscreen target is remade).
  o.width = 64;
  o.height = 48;
  Image img = renderer->render({{&sphere, {}, ""}}, o);
  EXPECT_EQ(img.width, 64);
  EXPECT_EQ(img.height, 48);
}

TEST_F(RendererTest, MeshWithoutNormalsGetsThemComputed) {
  Mesh sphere = makeSphere();
  Mesh bare = sphere;
  bare.normals.clear();
  Image a = renderer->render({{&sphere, {}, ""}}, smallOptions());
  Image b = renderer->render({{&bare, {}, ""}}, smallOptions());
  int worse = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) worse += maxChannelDiff(a, b, x, y) > 12;
  EXPECT_LT(worse, a.width * a.height / 100);
}

TEST_F(RendererTest, PngRoundTrips) {
  Mesh sphere = makeSphere();
  std::vector<float> height;
  for (const auto& p : sphere.positions) height.push_back(float(p.z));
  Image img = renderer->render({{&sphere, height, "round trip"}}, smallOptions());
  fs::path dir = fs::temp_directory_path() / ("sffd_render_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string path = (dir / "sphere.png").string();
  writePng(path, img);
  Image back = readPng(path);
  ASSERT_EQ(back.width, img.width);
  ASSERT_EQ(back.height, img.height);
  ASSERT_EQ(back.rgba.size(), img.rgba.size());
  EXPECT_EQ(back.rgba, img.rgba);   // RGB written exactly, alpha opaque
  // Nothing but the picture is left in the folder (no temporary file).
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1u);
  // An unwritable place is an input error and leaves nothing.
  try {
    writePng((dir / "no" / "such" / "x.png").string(), img);
    FAIL() << "wrote into a folder that does not exist";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
  }
  // Not a PNG: an input error.
  std::string text = (dir / "text.png").string();
  std::ofstream(text) << "not a png\n";
  try {
    readPng(text);
    FAIL() << "read a text file as a PNG";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
  }
  fs::remove_all(dir);
}

// SFFD_RENDER_TEST_PICTURES=DIR keeps sample pictures there, to look at (skipped otherwise).
TEST_F(RendererTest, SamplePictures) {
  const char* dir = std::getenv("SFFD_RENDER_TEST_PICTURES");
  if (!dir || !*dir) GTEST_SKIP() << "set SFFD_RENDER_TEST_PICTURES=DIR to keep sample pictures";
  Mesh a = makeSphere(1.0, glm::dvec3(0), 24, 12), b = makeSphere(1.0, glm::dvec3(0), 96, 48);
  std::vector<float> height;
  for (const auto& p : b.positions) height.push_back(float(p.z * 0.02));
  RenderOptions o;
  o.width = 960;
  o.height = 480;
  o.wireframe = true;
  writePng(std::string(dir) + "/spheres.png", renderer->render({{&a, {}, "coarse (24x12)"}, {&b, height, "height, x0.02"}}, o));
}

// EGL and OSMesa are two ways to the same Mesa: their pictures agree within a small tolerance.
TEST(RendererProviders, EglAndOSMesaAgree) {
  SKIP_WITHOUT_LIBRARY(Provider::EGL);
  SKIP_WITHOUT_LIBRARY(Provider::OSMesa);
  Mesh sphere = makeSphere();
  std::vector<float> height;
  for (const auto& p : sphere.positions) height.push_back(float(p.z));
  RenderOptions o = smallOptions();
  o.wireframe = true;
  Image images[2];
  std::string names[2];
  int k = 0;
  for (Provider p : {Provider::EGL, Provider::OSMesa}) {
    auto r = Renderer::createHeadless(p);
    names[k] = std::string(providerName(p)) + " (" + r->deviceName() + ")";
    images[k++] = r->render({{&sphere, height, "sphere"}}, o);
  }
  ASSERT_EQ(images[0].rgba.size(), images[1].rgba.size());
  int worst = 0;
  size_t off = 0;
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      int d = maxChannelDiff(images[0], images[1], x, y);
      worst = std::max(worst, d);
      off += d > 4;
    }
  EXPECT_LE(off, size_t(o.width * o.height / 500)) << names[0] << " vs " << names[1];
  EXPECT_LE(worst, 48) << names[0] << " vs " << names[1];
  std::printf("%s vs %s: max channel difference %d, %zu pixels off by more than 4\n", names[0].c_str(),
              names[1].c_str(), worst, off);
}

// The renderer on a context made elsewhere (the viewer's case), several renderers in one process, and a
// compute context in between: each activates its own context.
TEST(RendererProviders, SharesTheProcessWithOtherContexts) {
  SKIP_WITHOUT_LIBRARY(Provider::EGL);
  std::shared_ptr<Context> ctx(createEglContext());
  Renderer a(ctx);
  auto b = Renderer::createHeadless(Provider::EGL);
  Mesh sphere = makeSphere(1.0, glm::dvec3(0), 32, 16);
  Image ia = a.render({{&sphere, {}, ""}}, smallOptions());
  Image ib = b->render({{&sphere, {}, ""}}, smallOptions());
  EXPECT_EQ(ia.rgba, ib.rgba);
  auto other = createEglContext();   // current now
  Image again = a.render(smallOptions());
  EXPECT_EQ(again.rgba, ia.rgba);
}

TEST(UpAxis, AutoIsYForGltfAndZOtherwise) {
  EXPECT_EQ(upAxisFor("auto", "a/scene.GLB"), UpAxis::PosY);
  EXPECT_EQ(upAxisFor("auto", "scene.gltf"), UpAxis::PosY);
  EXPECT_EQ(upAxisFor("auto", "part.stl"), UpAxis::PosZ);
  EXPECT_EQ(upAxisFor("auto", "teapot.bpt"), UpAxis::PosZ);
  EXPECT_EQ(upAxisFor("-x", "scene.glb"), UpAxis::NegX);
  EXPECT_EQ(upAxisFor("+y", "part.stl"), UpAxis::PosY);
  EXPECT_THROW(upAxisFor("up", "part.stl"), sffd::Error);
}

}  // namespace
}  // namespace sffd::gl
