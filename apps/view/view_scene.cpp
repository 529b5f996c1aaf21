// Scene (view_scene.h): the deformation paths of the viewer and what each gives the renderer.
#include "apps/view/view_scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <glad/gl.h>

#include <sffd/error.h>
#include "analysis/error_metrics.h"
#include "backends/opengl/gl_backend.h"
#include "model/lattice_pack.h"
#include "model/mesh_topology.h"
#include "core/wall_clock.h"
#include "pipelines/deformer_internal.h"

namespace sffd::view {

std::vector<float> geometryErrors(const Mesh& input, const Lattice& lattice, const PatchVertices& pv) {
  PackedLattice packed = packLattice(lattice);
  ExactReference ref(input, packed);
  std::vector<float> out(pv.vertexCount());
  const size_t nv = size_t(tessVertexCount(pv.level));
  for (size_t v = 0; v < pv.vertexCount(); ++v) {
    glm::dvec3 x, n, xr, nr;
    ref.preImage(pv.parent[v / nv], glm::dvec3(pv.lamParent[3 * v], pv.lamParent[3 * v + 1], pv.lamParent[3 * v + 2]), x, n);
    ref.deform(x, n, xr, nr);
    out[v] = float(glm::length(glm::dvec3(pv.position[3 * v], pv.position[3 * v + 1], pv.position[3 * v + 2]) - xr));
  }
  return out;
}

Scene::Scene(gl::Renderer& renderer, Device& device, bool zeroCopy, Mesh mesh, DeformOptions options, int draftLevel)
    : renderer_(renderer),
      device_(device),
      zeroCopy_(zeroCopy),
      mesh_(std::move(mesh)),
      options_(std::move(options)),
      level_(options_.tess),
      draftLevel_(draftLevel > 0 && draftLevel < level_ ? draftLevel : 0),
      activeLevel_(level_) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const auto& p : mesh_.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  if (!mesh_.positions.empty()) normalLength_ = float(0.03 * glm::length(hi - lo));
}

Scene::~Scene() {
  active_ = nullptr;
  draft_.reset();
  deformer_.reset();
  try {
    renderer_.context().activate();
    if (hostTess_) glDeleteBuffers(1, &hostTess_);
    if (sessionIndex_) glDeleteBuffers(1, &sessionIndex_);
  } catch (...) {
  }
}

std::string Scene::path() const { return path_; }

void Scene::update(const Lattice& lattice, const SceneSettings& settings,
                   const std::function<void(const std::string&)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const bool smooth = settings.method == "smooth", knotBox = settings.clip == "knot-box";
  if (!deformer_ || settings.method != deformerSettings_.method || (smooth && settings.clip != deformerSettings_.clip) ||
      !sameLatticeStructure(lattice, deformerLattice_)) {
    if (progress && smooth)
      progress("PREPARING: PN TRIANGLES AND " + std::string(knotBox ? "KNOT-BOX" : "REGULAR") + " CLIPPING OF " +
               std::to_string(mesh_.triangles.size()) + " TRIANGLES");
    else if (progress && !drawn_.positions.size())
      progress("PREPARING: " + settings.method + " FFD");
    active_ = nullptr;
    draft_.reset();
    deformer_.reset();
    deformer_ = makeDeformer(lattice, settings, level_);
    deformerLattice_ = lattice;
    deformerSettings_ = settings;
  }
  // A draft: the same method at a lower level, so that a frame while dragging draws a tenth of the
  // triangles (classic FFD has no level).
  const bool draft = settings.draft && draftLevel_ > 0 && settings.method != "classic";
  if (draft && !draft_) {
    if (progress) progress("PREPARING THE DRAFT (LEVEL " + std::to_string(draftLevel_) + ") SHOWN WHILE DRAGGING");
    draft_ = makeDeformer(lattice, settings, draftLevel_);
  }
  active_ = draft ? draft_.get() : deformer_.get();
  activeLevel_ = draft ? draftLevel_ : level_;
  Deformer& deformer = *active_;
  const Timings& t = deformer.deform(lattice);
  times_.pnMs = t.pnMs;
  times_.clipMs = t.clipMs;
  times_.deformMs = t.deformMs;
  subTriangles_ = deformer.subTriangles();
  // Straight from the device buffers, which hold positions in the Deformer's local frame (a model far
  // from the world origin, or of an unusual size): the renderer and the overlays take that frame.
  if (smooth && zeroCopy_ && !settings.heatmap) {
    drawSession({});
    path_ = "zero-copy";
  } else {
    std::optional<PatchVertices> pv = deformer.internal().run->patchVertices();
    Mesh mesh = settings.heatmap && pv ? Mesh{} : pv ? weldPatchVertices(*pv) : deformer.result();
    drawHost(deformer.internal().input, lattice, std::move(mesh), pv, settings);
    // The names the HUD and --stats have always given: smooth on a device, or the others.
    path_ = smooth && device_.info().api != "cpu" ? "session+copy" : "host";
  }
  times_.updateMs = msSince(t0);
}

std::unique_ptr<Deformer> Scene::makeDeformer(const Lattice& lattice, const SceneSettings& settings, int level) {
  DeformOptions o = options_;
  o.method = settings.method == "smooth" ? Method::Smooth : settings.method == "accurate" ? Method::Accurate : Method::Classic;
  o.clip = settings.clip == "knot-box" ? Clip::KnotBox : Clip::Regular;
  o.tess = level;
  return std::make_unique<Deformer>(device_, mesh_, lattice, o);
}

void Scene::drawHost(const Mesh& input, const Lattice& lattice, Mesh mesh, const std::optional<PatchVertices>& patches,
                     const SceneSettings& settings) {
  drawingSession_ = false;
  std::vector<float> scalars;
  if (settings.heatmap) {
    PatchVertices hp = patches ? *patches : linearPatchVertices(mesh, level_);
    scalars = geometryErrors(input, lattice, hp);
    result_ = patches ? weldPatchVertices(*patches) : mesh;
    if (!patches) uploadTess(linearPatchVertices(mesh, 1));
    drawn_ = unweldedPatchMesh(hp);
  } else {
    if (!patches) uploadTess(linearPatchVertices(mesh, 1));
    result_ = mesh;
    drawn_ = std::move(mesh);
  }
  if (patches) uploadTess(*patches);
  renderer_.setItems({{&drawn_, scalars, ""}});
  outputTriangles_ = drawn_.triangles.size();
}

void Scene::uploadTess(const PatchVertices& pv) {
  renderer_.context().activate();
  const size_t nv = size_t(tessVertexCount(pv.level));
  std::vector<float> data(pv.patchCount() * 2 * nv * 4, 0.0f);
  for (size_t p = 0; p < pv.patchCount(); ++p)
    for (size_t v = 0; v < nv; ++v) {
      const size_t src = 3 * (p * nv + v);
      float* pos = &data[(2 * nv * p + v) * 4];
      float* nor = &data[(2 * nv * p + nv + v) * 4];
      for (int c = 0; c < 3; ++c) pos[c] = float(pv.position[src + c]), nor[c] = float(pv.normal[src + c]);
    }
  if (!hostTess_) glGenBuffers(1, &hostTess_);
  glBindBuffer(GL_ARRAY_BUFFER, hostTess_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_DYNAMIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  tess_ = {{hostTess_, pv.patchCount(), pv.level}};
}

void Scene::drawSession(const std::vector<glm::dvec3>& fitPoints) {
  renderer_.context().activate();
  // The deform kernel wrote the buffers as storage; they are read as vertex attributes next.
  glMemoryBarrier(GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | GL_ELEMENT_ARRAY_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  const std::vector<OutputChunk> chunks = active_->deviceOutput();
  const int L = activeLevel_;
  const size_t nv = size_t(tessVertexCount(L)), nt = size_t(tessTriangleCount(L));
  size_t maxCount = 0;
  for (const auto& c : chunks) maxCount = std::max(maxCount, c.count);
  if (maxCount > sessionIndexPatches_ || L != sessionIndexLevel_) {
    // One index list for every chunk: patch p's triangles at vertex offset 2 * nv * p.
    std::vector<uint32_t> local = tessTriangles(L), all;
    all.reserve(maxCount * local.size());
    for (size_t p = 0; p < maxCount; ++p)
      for (uint32_t i : local) all.push_back(uint32_t(2 * nv * p + i));
    if (!sessionIndex_) glGenBuffers(1, &sessionIndex_);
    glBindBuffer(GL_ARRAY_BUFFER, sessionIndex_);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(all.size() * 4), all.data(), GL_STATIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    sessionIndexPatches_ = maxCount;
    sessionIndexLevel_ = L;
  }
  gl::BufferItem item;
  item.origin = active_->localOrigin();
  item.scale = active_->localScale();
  item.fitPoints.reserve(fitPoints.size());
  for (const glm::dvec3& p : fitPoints) item.fitPoints.push_back(glm::vec3((p - item.origin) * item.scale));
  tess_.clear();
  outputTriangles_ = 0;
  for (const auto& c : chunks) {
    const unsigned buffer = gl::glBufferObject(device_.backend(), c.buffer);
    if (!buffer) throw Error(ErrorKind::Internal, "view: the Deformer's buffer is not a GL buffer of the window");
    item.draws.push_back({buffer, sessionIndex_, 0, nv * 16, c.count * nt * 3});
    tess_.push_back({buffer, c.count, L, item.origin, item.scale});
    outputTriangles_ += c.count * nt;
  }
  renderer_.setBufferItem(item);
  drawingSession_ = true;
}

std::vector<glm::dvec3> Scene::resultPoints() {
  if (!drawingSession_) return drawn_.positions;
  const PatchVertices pv = *active_->internal().run->patchVertices();
  std::vector<glm::dvec3> pts(pv.vertexCount());
  for (size_t v = 0; v < pts.size(); ++v) pts[v] = {pv.position[3 * v], pv.position[3 * v + 1], pv.position[3 * v + 2]};
  return pts;
}

void Scene::prepareFit() {
  if (drawingSession_) drawSession(resultPoints());
}

Mesh Scene::resultMesh() {
  if (drawingSession_) return active_->result();
  return result_;
}

}  // namespace sffd::view
