// Orbit, pan and zoom of the viewer's camera on top of the renderer's view direction (azimuth and
// elevation as `sffd render --view`), and the screen-space maths of picking and dragging control
// points. Pixels count from the top left of the framebuffer. No GL calls.
#pragma once
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "apps/render/gl_renderer.h"

namespace sffd::view {

class OrbitCamera {
 public:
  // Takes the fitted camera of a picture (Renderer::cameras without a placement) as the placement.
  void fitTo(const gl::SlotCamera& fitted, double sceneRadius);
  bool placed() const { return placement_.has_value(); }
  void orbit(gl::RenderOptions& o, double dAzimuthDeg, double dElevationDeg);
  // Moves the target by a pixel offset in the view plane (the scene follows the cursor).
  void pan(const gl::SlotCamera& cam, double dxPixels, double dyPixels);
  void zoom(double factor);
  // Writes the placement into the options (nothing before the first fit: the renderer fits).
  void apply(gl::RenderOptions& o) const;

 private:
  void updateDepthRange();
  std::optional<gl::RenderOptions::Placement> placement_;
  double radius_ = 1;
};

// (x, y) pixels from the top left and the window depth (0 near .. 1 far; outside when behind the eye).
glm::dvec3 projectToPixel(const gl::SlotCamera& cam, const glm::dvec3& world, int framebufferHeight);
// The model-space vector that moves a point at `at` by (dx, dy) pixels in the view plane.
glm::dvec3 pixelDeltaToWorld(const gl::SlotCamera& cam, const glm::dvec3& at, double dx, double dy);
// The point nearest to pixel (x, y) within `radius` pixels and in front of the eye (the nearer one on a
// tie); nullopt when none.
std::optional<size_t> pickPoint(const gl::SlotCamera& cam, const std::vector<glm::dvec3>& points, int framebufferHeight,
                                double x, double y, double radius);
// The points that project inside the pixel rectangle (any corner order) and lie in front of the eye.
std::vector<size_t> pointsInBox(const gl::SlotCamera& cam, const std::vector<glm::dvec3>& points,
                                int framebufferHeight, double x0, double y0, double x1, double y1);

}  // namespace sffd::view
