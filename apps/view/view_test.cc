// Unit tests of the viewer's GL-free parts: the script parser and key table, the undo history, and
// the picking maths (projection, pick, pixel drags).
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <sffd/error.h>
#include "apps/view/view_camera.h"
#include "apps/view/view_edit.h"
#include "apps/view/view_script.h"

namespace sffd::view {
namespace {

TEST(ViewScript, ParsesCommands) {
  EXPECT_FALSE(parseCommand("   # only a comment"));
  EXPECT_FALSE(parseCommand(""));
  auto c = parseCommand("drag 1 2 3 0.5 -1e-2 0  # trailing comment");
  ASSERT_TRUE(c);
  EXPECT_EQ(c->verb, "drag");
  EXPECT_EQ(c->numbers, (std::vector<double>{1, 2, 3, 0.5, -0.01, 0}));
  EXPECT_EQ(parseCommand("select all")->words[0], "all");
  EXPECT_EQ(parseCommand("select 0 0 0 1 1 1")->numbers.size(), 6u);
  EXPECT_EQ(parseCommand("set heatmap on")->words[1], "on");
  for (const char* bad : {"drag 1 2 3", "drag 1.5 2 3 0 0 0", "select 1 2", "select -1 0 0", "method fast",
                          "set heatmap maybe", "resize -1 10", "zoom 0", "screenshot", "nonsense", "view 1 inf"})
    EXPECT_THROW(parseCommand(bad), Error) << bad;
}

TEST(ViewScript, EveryKeyIsACommand) {
  for (const auto& [key, help] : keyBindings()) {
    auto c = keyCommand(key);
    ASSERT_TRUE(c) << key;
    EXPECT_FALSE(help.empty());
  }
  EXPECT_EQ(keyCommand("ctrl+z")->verb, "undo");
  EXPECT_EQ(keyCommand("shift+ctrl+z")->verb, "redo");
  EXPECT_FALSE(keyCommand("ctrl+q"));
}

Lattice smallLattice() { return makeIdentityLattice({-1, -1, -1}, {1, 1, 1}, {3, 4, 5}, {2, 2, 2}); }

TEST(ViewEdit, UndoRedoAreExact) {
  LatticeEdit e(smallLattice());
  const auto p0 = e.lattice().controlPoints;
  e.select({3, 7});
  e.beginGesture();
  for (int i = 0; i < 10; ++i) e.moveSelected({0.1, 1.0 / 3, -0.7});   // one gesture: one step
  e.endGesture();
  const auto p1 = e.lattice().controlPoints;
  e.moveSelected({1e-17, 0, 0});
  e.selectAll();
  e.moveSelected({0.25, 0, 0});
  const auto p3 = e.lattice().controlPoints;
  EXPECT_TRUE(e.undo());
  EXPECT_TRUE(e.undo());
  EXPECT_EQ(e.lattice().controlPoints, p1);
  EXPECT_TRUE(e.undo());
  EXPECT_EQ(e.lattice().controlPoints, p0);
  EXPECT_FALSE(e.undo());
  EXPECT_TRUE(e.redo());
  EXPECT_TRUE(e.redo());
  EXPECT_TRUE(e.redo());
  EXPECT_EQ(e.lattice().controlPoints, p3);
  EXPECT_FALSE(e.redo());
  // A new step after an undo drops the redo list.
  e.undo();
  e.moveSelected({0, 0, 1});
  EXPECT_FALSE(e.canRedo());
  // replace() with a smaller lattice keeps only valid selections.
  e.select({59});
  e.replace(makeIdentityLattice({-1, -1, -1}, {1, 1, 1}, {3, 3, 3}, {2, 2, 2}));
  EXPECT_TRUE(e.selection().empty());
  EXPECT_TRUE(e.undo());
  EXPECT_EQ(e.lattice().pointCount(), 60u);
}

gl::SlotCamera camera() {
  gl::SlotCamera c;
  c.width = 400;
  c.height = 300;
  c.fovYDeg = 30;
  c.aspect = 400.0 / 300;
  c.eye = {0, -5, 1};
  c.target = {0, 0, 0};
  c.up = {0, 0, 1};
  c.zNear = 0.1;
  c.zFar = 20;
  c.view = glm::lookAt(c.eye, c.target, c.up);
  c.projection = glm::perspective(glm::radians(c.fovYDeg), c.aspect, c.zNear, c.zFar);
  return c;
}

TEST(ViewCamera, PickAndDragInScreenSpace) {
  const gl::SlotCamera cam = camera();
  std::vector<glm::dvec3> pts = {{0, 0, 0}, {0.5, 0, 0.2}, {0, 3, 0}, {0, -10, 0}};   // the last is behind the eye
  glm::dvec3 t = projectToPixel(cam, {0, 0, 0}, 300);
  EXPECT_NEAR(t.x, 200, 1e-9);
  EXPECT_NEAR(t.y, 150, 1e-9);
  glm::dvec3 a = projectToPixel(cam, pts[1], 300);
  EXPECT_EQ(pickPoint(cam, pts, 300, a.x + 3, a.y - 2, 12), std::optional<size_t>(1));
  EXPECT_FALSE(pickPoint(cam, pts, 300, 5, 5, 12));
  // Moving a point by the world vector for (dx, dy) pixels moves its projection by (dx, dy).
  glm::dvec3 moved = pts[1] + pixelDeltaToWorld(cam, pts[1], 17, -9);
  glm::dvec3 b = projectToPixel(cam, moved, 300);
  EXPECT_NEAR(b.x - a.x, 17, 0.2);
  EXPECT_NEAR(b.y - a.y, -9, 0.2);
  auto inBox = pointsInBox(cam, pts, 300, 400, 300, 0, 0);
  EXPECT_EQ(inBox, (std::vector<size_t>{0, 1, 2}));
}

TEST(ViewCamera, OrbitPanZoomKeepAValidPlacement) {
  OrbitCamera oc;
  gl::RenderOptions o;
  oc.apply(o);
  EXPECT_FALSE(o.placement);   // before a fit the renderer fits
  oc.fitTo(camera(), 1.0);
  oc.zoom(2);
  oc.orbit(o, 400, 200);
  EXPECT_LE(o.elevationDeg, 89);
  oc.pan(camera(), 10, 0);
  oc.apply(o);
  ASSERT_TRUE(o.placement);
  EXPECT_GT(o.placement->zNear, 0);
  EXPECT_GT(o.placement->zFar, o.placement->zNear);
  EXPECT_NEAR(o.placement->distance, glm::length(camera().eye) / 2, 1e-9);
}

}  // namespace
}  // namespace sffd::view
