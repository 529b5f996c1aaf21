// What `sffd view` draws and how it is computed. Two paths:
//  - device-resident: --method smooth on a GPU backend goes through DeformSession (pre-compute once,
//    deform on every move). On the GL backend of the window's own context the renderer draws the
//    session's tessellation buffers in place (zero copy); on another backend (Vulkan) the output is
//    downloaded and uploaded to GL;
//  - host: every other case (accurate, classic, the CPU reference, the heat map) runs the same job
//    functions as `sffd deform/render` (HostDeform, given by apps/sffd/cmd_view.cpp) and uploads the mesh.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/backend.h"
#include "pipelines/deform_session.h"
#include "apps/render/gl_renderer.h"
#include "model/lattice.h"
#include "model/mesh.h"
#include "pipelines/patch_output.h"
#include "apps/view/view_draw.h"

namespace sffd::view {

struct HostResult {
  Mesh input;                             // the input as the method prepared it (pre-images index its triangles)
  Mesh mesh;                              // the result, as `sffd deform` writes it
  std::optional<PatchVertices> patches;   // smooth and accurate
  double pnMs = 0, clipMs = 0, deformMs = 0;
};
using HostDeform = std::function<HostResult(const Lattice& lattice, const std::string& method, const std::string& clip)>;

struct SceneSettings {
  std::string method = "smooth", clip = "regular";
  bool heatmap = false;
};

struct StageTimes {
  double pnMs = 0, clipMs = 0, deformMs = 0;   // the stages of the last update (pn, clip: of its pre-compute)
  double updateMs = 0;                         // wall time of the last update, uploads included
};

class Scene {
 public:
  // `gpu` may be null (CPU reference). `zeroCopy`: gpu is a GL backend on the renderer's context.
  // `mesh` is the input as loaded (DeformSession applies the crease angle of its options itself).
  Scene(gl::Renderer& renderer, Backend* gpu, bool zeroCopy, Mesh mesh, HostDeform host,
        std::optional<DeformSessionOptions> sessionOptions, int level);
  ~Scene();

  // Deforms with the lattice and settings and sets up the drawing. `progress` is told before slow
  // steps (pre-compute). Throws an Error on failure; what was drawn before stays.
  void update(const Lattice& lattice, const SceneSettings& settings,
              const std::function<void(const std::string&)>& progress = {});

  const StageTimes& times() const { return times_; }
  std::string path() const;                      // "zero-copy", "session+copy" or "host", for the HUD
  const std::vector<TessSource>& tessSources() const { return tess_; }
  size_t subTriangles() const { return subTriangles_; }
  size_t outputTriangles() const { return outputTriangles_; }
  // Positions of the result (downloaded on the zero-copy path): what `fit` frames.
  std::vector<glm::vec3> resultPoints();
  // Gives the renderer the result's positions, so that Renderer::cameras() can fit them.
  void prepareFit();
  // The result mesh as `sffd deform` would write it.
  Mesh resultMesh();
  float normalLength() const { return normalLength_; }

 private:
  void drawHost(const Mesh& input, const Lattice& lattice, Mesh mesh, const std::optional<PatchVertices>& patches,
                const SceneSettings& settings);
  void uploadTess(const PatchVertices& pv);
  void drawSession(std::vector<glm::vec3> fitPoints);
  bool sessionUsable(const Lattice& lattice, const SceneSettings& settings) const;

  gl::Renderer& renderer_;
  Backend* gpu_;
  bool zeroCopy_;
  Mesh sessionMesh_;                // as loaded: what DeformSession prepares
  Mesh creasedMesh_;                // with the crease angle applied: the heat map's pre-images
  HostDeform host_;
  std::optional<DeformSessionOptions> sessionOptions_;
  int level_;
  std::unique_ptr<DeformSession> session_;
  Lattice sessionLattice_;          // the structure the session was made for
  bool sessionClipKnotBox_ = false;
  std::optional<SubTriangleRecords> sessionRecords_;
  bool drawingSession_ = false;     // the renderer draws the session's buffers
  Mesh drawn_;                      // host path: the mesh given to the renderer
  Mesh result_;                     // host path: the result as deform writes it
  unsigned hostTess_ = 0, sessionIndex_ = 0;
  size_t sessionIndexPatches_ = 0;
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
