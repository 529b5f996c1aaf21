// What `sffd view` draws and how it is computed: an sffd::Deformer for the method, clipping and
// lattice structure shown (prepared once, deformed on every move). Smooth FFD on the GL backend of the
// window's own context is drawn from the Deformer's tessellation buffers in place (zero copy); every
// other case (another device, accurate, classic, the heat map) downloads the result and uploads it to GL.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/backend.h"
#include <sffd/deformer.h>
#include "apps/render/gl_renderer.h"
#include "model/lattice.h"
#include "model/mesh.h"
#include "pipelines/patch_output.h"
#include "apps/view/view_draw.h"

namespace sffd::view {

struct SceneSettings {
  std::string method = "smooth", clip = "regular";
  bool heatmap = false;
  bool draft = false;   // this update is a frame while dragging: smooth and accurate at the Scene's draft level
};

struct StageTimes {
  double pnMs = 0, clipMs = 0, deformMs = 0;   // the stages of the last update (pn, clip: of its pre-compute)
  double updateMs = 0;                         // wall time of the last update, uploads included
};

class Scene {
 public:
  // `zeroCopy`: the device is a GL backend on the renderer's context. `mesh` is the input as loaded
  // (the Deformer applies the crease angle of `options` itself); `options` as for `sffd deform`, the
  // method and clipping coming from each update's settings. `draftLevel`: the tessellation level of
  // draft updates (a second Deformer, prepared at the first one and kept; 0, or not below
  // options.tess: drafts are full updates).
  Scene(gl::Renderer& renderer, Device& device, bool zeroCopy, Mesh mesh, DeformOptions options, int draftLevel = 0);
  ~Scene();

  // Deforms with the lattice and settings and sets up the drawing. `progress` is told before slow
  // steps (pre-compute). Throws an Error on failure; what was drawn before stays.
  void update(const Lattice& lattice, const SceneSettings& settings,
              const std::function<void(const std::string&)>& progress = {});

  const StageTimes& times() const { return times_; }
  bool drawingDraft() const { return activeLevel_ != level_; }   // the last update was a draft
  bool draftsOn() const { return draftLevel_ > 0; }               // a draft level below the full one was given
  int level() const { return activeLevel_; }                     // the tessellation level drawn
  std::string path() const;                      // "zero-copy", "session+copy" (smooth, downloaded) or "host" (others), for the HUD
  const std::vector<TessSource>& tessSources() const { return tess_; }
  size_t subTriangles() const { return subTriangles_; }
  size_t outputTriangles() const { return outputTriangles_; }
  // Positions of the result (downloaded on the zero-copy path): what `fit` frames.
  std::vector<glm::dvec3> resultPoints();
  // Gives the renderer the result's positions, so that Renderer::cameras() can fit them.
  void prepareFit();
  // The result mesh as `sffd deform` would write it.
  Mesh resultMesh();
  float normalLength() const { return normalLength_; }

 private:
  void drawHost(const Mesh& input, const Lattice& lattice, Mesh mesh, const std::optional<PatchVertices>& patches,
                const SceneSettings& settings);
  void uploadTess(const PatchVertices& pv);
  void drawSession(const std::vector<glm::dvec3>& fitPoints);   // world positions
  std::unique_ptr<Deformer> makeDeformer(const Lattice& lattice, const SceneSettings& settings, int level);

  gl::Renderer& renderer_;
  Device& device_;
  bool zeroCopy_;
  Mesh mesh_;                       // as loaded: what the Deformer prepares
  DeformOptions options_;
  int level_;
  int draftLevel_, activeLevel_;
  std::unique_ptr<Deformer> deformer_, draft_;   // at level_, at draftLevel_ (made at the first draft)
  Deformer* active_ = nullptr;                   // the one the last update used
  Lattice deformerLattice_;         // the structure the Deformer was made for
  SceneSettings deformerSettings_;  // the method and clipping it was made for
  bool drawingSession_ = false;     // the renderer draws the Deformer's buffers
  Mesh drawn_;                      // host path: the mesh given to the renderer
  Mesh result_;                     // host path: the result as deform writes it
  unsigned hostTess_ = 0, sessionIndex_ = 0;
  size_t sessionIndexPatches_ = 0;
  int sessionIndexLevel_ = 0;
  std::vector<TessSource> tess_;
  StageTimes times_;
  size_t subTriangles_ = 0, outputTriangles_ = 0;
  float normalLength_ = 0.02f;
  std::string path_ = "host";
};

// Geometry error (distance to the exact FFD of its pre-image) of every tessellation vertex, as
// `sffd render --color-by geometry` colours it.
std::vector<float> geometryErrors(const Mesh& input, const Lattice& lattice, const PatchVertices& pv);
// Every patch vertex its own vertex (so each can carry its own error).
Mesh unweldedMesh(const PatchVertices& pv);

}  // namespace sffd::view
