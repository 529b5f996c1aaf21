// Offscreen (and on-screen) pictures of meshes on a GL 4.3+ core context: smooth Phong shading with
// two-sided lighting (key + fill + rim light, hemisphere ambient, gamma-correct), an optional
// per-vertex scalar coloured with viridis and a legend bar, an optional wireframe overlay, several
// meshes side by side with captions, and PNG output through libpng.
//
// The renderer is drawing code, not compute: it never touches the Backend interface and owns its
// context (EGL surfaceless by default, OSMesa as the fallback) or shares one the caller made (the
// interactive viewer's GLFW window). Like every user of a Context it activates it before its GL calls.
//
//   auto r = Renderer::createHeadless();
//   r->setItems({{&before, {}, "input"}, {&after, {}, "smooth"}});
//   Image img = r->render(options);
//   writePng("out.png", img);
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "apps/render/png_io.h"
#include "backends/opengl/gl_context.h"
#include "model/mesh.h"

namespace sffd::gl {

// One mesh of a picture. Items are drawn left to right, each in its own slot of equal width.
struct RenderItem {
  const Mesh* mesh = nullptr;     // positions, normals (recomputed when missing), triangles; read at setItems
  std::vector<float> scalars;     // empty, or one value per vertex: coloured with viridis
  std::string caption;            // drawn above the slot (A-Z, digits, punctuation; lower case shown upper)
};

enum class UpAxis { PosX, PosY, PosZ, NegX, NegY, NegZ };
// "x", "y", "z", "-x", "-y", "-z" (also "+x"...); throws an input Error otherwise.
UpAxis parseUpAxis(const std::string& text);
// The --up option of render and view: an axis as parseUpAxis reads it, or "auto": +y for glTF files
// (.gltf, .glb: the format defines +Y as up), +z otherwise (CAD's and the teapot's convention; files
// of the other formats carry no up axis, so y-up scans still need --up y).
UpAxis upAxisFor(const std::string& option, const std::string& meshPath);

struct RenderOptions {
  int width = 1200, height = 900;
  // View direction, the eye seen from the target: elevation above the plane normal to `up`, azimuth
  // around `up` from the front (-y for z up, +z for y up) towards the right (+x in both cases).
  double azimuthDeg = 30, elevationDeg = 20;
  UpAxis up = UpAxis::PosZ;
  double fovYDeg = 30;            // perspective, vertical field of view
  double fill = 0.9;              // the fitted meshes span this fraction of the slot's smaller side
  bool shareCamera = true;        // every slot seen from the same distance (same scale), each item centred
  bool wireframe = false;         // triangle edges over the shading
  int samples = 4;                // multisampling (clamped to GL_MAX_SAMPLES, fewer above 16 Mpixels; 1: none)
  std::optional<std::array<float, 2>> scalarRange;   // default: min and max over all items' scalars
  bool legend = true;             // colour bar with the range's ends when an item has scalars
  bool gradientBackground = true; // light grey, lighter at the top; false: flat
  glm::vec3 baseColor{0.80f, 0.79f, 0.76f};           // sRGB albedo where there are no scalars
  // A placed camera (the viewer's orbit, pan and zoom) instead of one fitted to the meshes: every slot
  // looks at `target` from `distance` along the view direction above, with these depth planes.
  struct Placement {
    glm::dvec3 target{0};
    double distance = 1, zNear = 0.01, zFar = 100;
  };
  std::optional<Placement> placement;
};

// Geometry already in GL buffers of the renderer's context (the viewer draws the deform kernels'
// output in place, without a host copy): float vec4 positions and normals read with a 16-byte stride
// from `vertexBuffer` at the given byte offsets, triangles from the uint32 `indexBuffer`. The caller
// owns the buffers and keeps them alive while the item is set.
struct BufferDraw {
  unsigned vertexBuffer = 0, indexBuffer = 0;
  size_t positionOffset = 0, normalOffset = 0, indexCount = 0;
};
struct BufferItem {
  std::vector<BufferDraw> draws;      // drawn together, in one slot
  std::vector<glm::vec3> fitPoints;   // positions a fitted camera frames, in the frame below (may be empty with a placement)
  std::string caption;
  // The frame of the buffers' positions: world = position / scale + origin (a Deformer's device output is
  // in its local frame: Deformer::localOrigin(), localScale()).
  glm::dvec3 origin{0.0};
  double scale = 1;
};

// The camera of one slot, as used to draw it (for tests and the viewer's picking).
struct SlotCamera {
  int x = 0, y = 0, width = 0, height = 0;   // viewport in pixels, y from the bottom
  glm::dvec3 eye{0}, target{0}, up{0, 0, 1};
  double fovYDeg = 30, aspect = 1, zNear = 0.1, zFar = 10;
  glm::dmat4 view{1}, projection{1};
};

// A rendered picture with the camera of each item's slot (for picking and tests).
struct Image : RgbaImage {
  std::vector<SlotCamera> cameras;   // one per item
  Image() = default;
  Image(RgbaImage pixels) : RgbaImage(std::move(pixels)) {}
};

class Renderer {
 public:
  // A renderer on its own headless context: `provider` Auto is SFFD_GL_PROVIDER when set, else EGL
  // surfaceless, then OSMesa. Throws a device Error naming every reason when no GL 4.3+ context is had.
  static std::unique_ptr<Renderer> createHeadless(Provider provider = Provider::Auto);
  // A renderer on a context the caller made (kept alive by the renderer). Throws a device Error below GL 4.3.
  explicit Renderer(std::shared_ptr<Context> context);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  Context& context() { return *context_; }
  std::string deviceName() const { return renderer_; }   // GL_RENDERER
  int maxSize() const { return maxSize_; }                // largest width or height render() accepts

  // Uploads the meshes (replacing the previous ones). Throws an input Error for a bad item (scalar
  // count, a triangle index out of range).
  void setItems(const std::vector<RenderItem>& items);
  // Replaces the items by one item drawn from the caller's GL buffers (see BufferItem).
  void setBufferItem(const BufferItem& item);
  // Draws the items into an offscreen framebuffer of options.width x options.height and reads it back.
  // Throws an input Error for a size outside 1..maxSize().
  Image render(const RenderOptions& options);
  Image render(const std::vector<RenderItem>& items, const RenderOptions& options) {
    setItems(items);
    return render(options);
  }
  // Draws into the framebuffer bound now (a viewer's window: framebuffer 0) of the given size; returns
  // the slot cameras. options.width/height are ignored.
  std::vector<SlotCamera> draw(const RenderOptions& options, int width, int height);
  // The cameras draw() would use for a picture of this size, without drawing.
  std::vector<SlotCamera> cameras(const RenderOptions& options, int width, int height);
  // Lines of text (the caption font) with their top-left corner at (x, y) pixels from the top left,
  // over a translucent panel, into the framebuffer bound now of the given size. Returns the scale
  // used (pixels per font cell; 0 picks one from the size).
  int drawText(const std::vector<std::string>& lines, int x, int y, int width, int height,
               glm::vec4 color = {0.1f, 0.1f, 0.12f, 1.0f}, int scale = 0);

 private:
  struct GpuMesh;
  struct Programs;
  struct Frame;
  Frame frame(const RenderOptions& options, int width, int height) const;
  void deleteMeshes();
  void ensureTarget(int width, int height, int samples);
  void releaseTarget();

  std::shared_ptr<Context> context_;
  std::string renderer_;
  int maxSize_ = 0, maxSamples_ = 1;
  std::unique_ptr<Programs> programs_;
  std::vector<std::unique_ptr<GpuMesh>> meshes_;
  glm::dvec3 sceneCentre_{0};   // subtracted from positions before they become float,
  double sceneScale_ = 1;       // then multiplied by this power of two that brings the scene to a size of 1
                                // to 2 (exact): the shaders' squared lengths stay in float's range at any size
  unsigned overlayVao_ = 0, overlayVbo_ = 0, emptyVao_ = 0;
  // offscreen target: multisampled colour + depth, resolved into a single-sample colour buffer
  int targetWidth_ = 0, targetHeight_ = 0, targetSamples_ = 0;
  unsigned msFbo_ = 0, msColor_ = 0, msDepth_ = 0, resolveFbo_ = 0, resolveColor_ = 0;
};

// Viridis, the perceptually uniform colormap (sRGB, t clamped to [0, 1]).
glm::vec3 viridis(float t);
// The legend's labels of lo and hi in one format: fixed, with three significant digits of the larger end, or
// both in scientific notation where that end is below 1e-3 or from 1e5 up.
std::array<std::string, 2> legendLabels(float lo, float hi);


}  // namespace sffd::gl
