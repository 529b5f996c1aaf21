// OrbitCamera and picking (view_camera.h).
#include "apps/view/view_camera.h"

#include <algorithm>
#include <cmath>

namespace sffd::view {

void OrbitCamera::fitTo(const gl::SlotCamera& fitted, double sceneRadius) {
  gl::RenderOptions::Placement p;
  p.target = fitted.target;
  p.distance = glm::length(fitted.eye - fitted.target);
  p.zNear = fitted.zNear;
  p.zFar = fitted.zFar;
  placement_ = p;
  radius_ = sceneRadius > 0 ? sceneRadius : 1;
  // The fitted planes are kept as they are, so that a fitted view draws exactly as render does.
}

void OrbitCamera::updateDepthRange() {
  if (!placement_) return;
  auto& p = *placement_;
  // The scene (and the lattice around it) may lie anywhere within a few radii of the target.
  const double reach = 3 * radius_ + glm::length(p.target) * 1e-9;
  p.zFar = p.distance + reach;
  p.zNear = std::max(p.distance - reach, p.zFar * 1e-4);
}

void OrbitCamera::orbit(gl::RenderOptions& o, double dAz, double dEl) {
  o.azimuthDeg = std::fmod(o.azimuthDeg + dAz, 360.0);
  o.elevationDeg = std::clamp(o.elevationDeg + dEl, -89.0, 89.0);
  updateDepthRange();
}

void OrbitCamera::pan(const gl::SlotCamera& cam, double dx, double dy) {
  if (!placement_) return;
  placement_->target -= pixelDeltaToWorld(cam, placement_->target, dx, dy);
  updateDepthRange();
}

void OrbitCamera::zoom(double factor) {
  if (!placement_ || !(factor > 0)) return;
  placement_->distance = std::clamp(placement_->distance / factor, radius_ * 1e-3, radius_ * 1e3);
  updateDepthRange();
}

void OrbitCamera::apply(gl::RenderOptions& o) const { o.placement = placement_; }

glm::dvec3 projectToPixel(const gl::SlotCamera& cam, const glm::dvec3& world, int fbHeight) {
  glm::dvec4 c = cam.projection * cam.view * glm::dvec4(world, 1.0);
  if (!(c.w > 0)) return {0, 0, -1};   // behind the eye
  glm::dvec3 ndc = glm::dvec3(c) / c.w;
  double x = cam.x + (ndc.x * 0.5 + 0.5) * cam.width;
  double yUp = cam.y + (ndc.y * 0.5 + 0.5) * cam.height;
  return {x, fbHeight - yUp, ndc.z * 0.5 + 0.5};
}

glm::dvec3 pixelDeltaToWorld(const gl::SlotCamera& cam, const glm::dvec3& at, double dx, double dy) {
  glm::dvec4 v = cam.view * glm::dvec4(at, 1.0);
  double depth = std::max(-v.z, 1e-9);
  double perPixel = 2 * depth * std::tan(glm::radians(cam.fovYDeg) / 2) / std::max(cam.height, 1);
  glm::dvec3 right(cam.view[0][0], cam.view[1][0], cam.view[2][0]);
  glm::dvec3 up(cam.view[0][1], cam.view[1][1], cam.view[2][1]);
  return (dx * right - dy * up) * perPixel;
}

std::optional<size_t> pickPoint(const gl::SlotCamera& cam, const std::vector<glm::dvec3>& points, int fbHeight,
                                double x, double y, double radius) {
  std::optional<size_t> best;
  double bestD = radius * radius, bestZ = 2;
  for (size_t i = 0; i < points.size(); ++i) {
    glm::dvec3 p = projectToPixel(cam, points[i], fbHeight);
    if (p.z < 0 || p.z > 1) continue;
    double d = (p.x - x) * (p.x - x) + (p.y - y) * (p.y - y);
    if (d < bestD - 1e-9 || (d <= bestD + 1e-9 && best && p.z < bestZ)) {
      best = i;
      bestD = d;
      bestZ = p.z;
    }
  }
  return best;
}

std::vector<size_t> pointsInBox(const gl::SlotCamera& cam, const std::vector<glm::dvec3>& points, int fbHeight,
                                double x0, double y0, double x1, double y1) {
  if (x0 > x1) std::swap(x0, x1);
  if (y0 > y1) std::swap(y0, y1);
  std::vector<size_t> out;
  for (size_t i = 0; i < points.size(); ++i) {
    glm::dvec3 p = projectToPixel(cam, points[i], fbHeight);
    if (p.z >= 0 && p.z <= 1 && p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1) out.push_back(i);
  }
  return out;
}

}  // namespace sffd::view
