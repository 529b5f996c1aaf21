// The viewer's own GL drawing, on the window's context next to the Renderer (gl_renderer.h):
//  - FrameTarget: each frame is drawn into a 4x multisampled framebuffer (as `sffd render` draws its
//    pictures; a draft frame while dragging into a single-sampled one), resolved, then copied to the
//    window; screenshots read the resolved pixels, so they are what the window shows;
//  - Overlays: lattice points and edges, the box-selection rectangle, and, from tessellation buffers
//    (DeformSession's layout: per patch nv float4 positions, then nv float4 normals), the sub-triangle
//    edges and the vertex normals.
#pragma once
#include <cstddef>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "apps/render/gl_renderer.h"
#include "model/lattice.h"

namespace sffd::view {

class FrameTarget {
 public:
  FrameTarget() = default;
  ~FrameTarget();
  FrameTarget(const FrameTarget&) = delete;
  FrameTarget& operator=(const FrameTarget&) = delete;
  // Binds a width x height target of `samples` samples a pixel (clamped to GL_MAX_SAMPLES; recreated
  // when either changes; sizes must be >= 1).
  void bind(int width, int height, int samples = 4);
  // Resolves the samples; then copies to the window's framebuffer (0) when `toWindow`.
  void resolve(bool toWindow);
  gl::Image read() const;   // the resolved pixels, rows from the top
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void release();
  int width_ = 0, height_ = 0, samples_ = 0;
  unsigned msFbo_ = 0, msColor_ = 0, msDepth_ = 0, fbo_ = 0, color_ = 0;
};

// One GL buffer holding `patches` tessellated patches of `level` in the layout above.
struct TessSource {
  unsigned buffer = 0;
  size_t patches = 0;
  int level = 10;
  // The frame of the buffer's positions: world = position / scale + origin (a Deformer's device output
  // is in its local frame, Deformer::localOrigin() and localScale(); a host upload is in the world's).
  glm::dvec3 origin{0.0};
  double scale = 1;
};

class Overlays {
 public:
  Overlays();   // needs the window's context current
  ~Overlays();
  Overlays(const Overlays&) = delete;
  Overlays& operator=(const Overlays&) = delete;

  // Edges between neighbouring control points and the points themselves (selected ones larger, red).
  void drawLattice(const gl::SlotCamera& cam, const Lattice& lattice, const std::vector<size_t>& selection);
  void drawRect(double x0, double y0, double x1, double y1, int width, int height);   // pixels from the top left
  void drawTessEdges(const gl::SlotCamera& cam, const std::vector<TessSource>& sources);
  void drawNormals(const gl::SlotCamera& cam, const std::vector<TessSource>& sources, float length);
  bool normalsSupported() const { return normalsProgram_ != 0; }

 private:
  void lines(const std::vector<float>& xyzrgba, unsigned mode, const glm::mat4& mvp, float pointSize);
  unsigned lineProgram_ = 0, tessProgram_ = 0, normalsProgram_ = 0;
  unsigned vao_ = 0, vbo_ = 0, tessVao_ = 0, edgeIndex_ = 0;
  size_t edgeIndexPatches_ = 0;
  int edgeIndexLevel_ = 0;
};

// Local vertex indices of the patch boundary at `level` as line segments (2 per segment, 3*level segments).
std::vector<uint32_t> tessBoundaryLines(int level);

}  // namespace sffd::view
