// Deformer: every method computes in coordinates local to the lattice box (docs/ROBUSTNESS.md
// "Models far from the origin"). The mesh and the lattice are translated on the host in double before
// anything reaches a device, and the results translated back in double, so float kernels keep their
// precision relative to the model's size wherever the model sits, on every backend alike (strict
// results stay identical across backends: they all see the same local inputs).
#include <algorithm>
#include <cmath>

#include "pipelines/deformer_internal.h"

namespace sffd {

namespace {
// `centre` rounded to a multiple of a power of two 8 to 16 times `extent`: 0 within about 4 extents
// of 0 (the computation then runs on the input's own bits, as before), else within 8 extents of it.
double roundedOrigin(double centre, double extent) {
  const double step = std::ldexp(1.0, std::ilogb(extent) + 4);
  return std::round(centre / step) * step;
}
}  // namespace

glm::dvec3 latticeLocalOrigin(const Lattice& lattice) {
  // The box's corners in world coordinates: x = frameLinear^-1 (p - frameOffset).
  const glm::dmat3 toWorld = glm::inverse(lattice.frameLinear);
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (int c = 0; c < 8; ++c) {
    glm::dvec3 p;
    for (int a = 0; a < 3; ++a) p[a] = (c >> a) & 1 ? lattice.domainHi(a) : lattice.domainLo(a);
    const glm::dvec3 x = toWorld * (p - lattice.frameOffset);
    lo = glm::min(lo, x), hi = glm::max(hi, x);
  }
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  glm::dvec3 origin;
  for (int a = 0; a < 3; ++a) origin[a] = roundedOrigin(0.5 * (lo[a] + hi[a]), extent);
  return origin;
}

Lattice localLattice(Lattice lattice, glm::dvec3 origin) {
  // World: x = x' + origin, so p = F x + o = F x' + (o + F origin). Parameters too (a native lattice's
  // knots are world coordinates): p = p' + q with q the domain's centre rounded, so the kernels'
  // parameters are as small as the box; knots - q is exact (Sterbenz) for a box far from 0.
  glm::dvec3 q;
  for (int a = 0; a < 3; ++a)
    q[a] = roundedOrigin(0.5 * (lattice.domainLo(a) + lattice.domainHi(a)), lattice.domainHi(a) - lattice.domainLo(a));
  for (glm::dvec3& p : lattice.controlPoints) p -= origin;
  lattice.frameOffset += lattice.frameLinear * origin - q;
  for (int a = 0; a < 3; ++a)
    for (double& k : lattice.knots[a]) k -= q[a];
  return lattice;
}

Mesh translatedMesh(Mesh mesh, glm::dvec3 by) {
  for (glm::dvec3& p : mesh.positions) p += by;
  return mesh;
}

namespace {

// Hands each piece to `to` with its positions moved by `by` (as translatedMesh).
class TranslatingSink final : public MeshSink {
 public:
  TranslatingSink(MeshSink& to, glm::dvec3 by) : to_(to), by_(by) {}
  void begin(const Mesh& tables) override { to_.begin(tables); }
  void add(const Mesh& piece, size_t firstVertex) override {
    moved_ = piece;
    for (glm::dvec3& p : moved_.positions) p += by_;
    to_.add(moved_, firstVertex);
  }
  void end() override { to_.end(); }

 private:
  MeshSink& to_;
  glm::dvec3 by_;
  Mesh moved_;
};

// A method run on local inputs whose results are handed out in world coordinates (except
// deviceOutput(), which stays on the device in local coordinates: Deformer::localOrigin()).
class LocalFrameRun final : public MethodRun {
 public:
  LocalFrameRun(std::unique_ptr<MethodRun> local, glm::dvec3 origin) : local_(std::move(local)), origin_(origin) {}

  void deform(const Lattice& lattice, Timings& timings, const ProgressReporter& progress) override {
    local_->deform(localLattice(lattice, origin_), timings, progress);
  }
  Mesh result(const ProgressReporter& progress) const override { return translatedMesh(local_->result(progress), origin_); }
  void streamResult(MeshSink& sink, const ProgressReporter& progress) const override {
    TranslatingSink moved(sink, origin_);
    local_->streamResult(moved, progress);
  }
  std::vector<OutputChunk> deviceOutput() const override { return local_->deviceOutput(); }
  size_t subTriangles() const override { return local_->subTriangles(); }
  std::vector<double> patchControlPoints() const override {
    // 20 points (x, y, z, 0) a sub-triangle: 10 of the geometry patch (translated), 10 of the normals.
    std::vector<double> points = local_->patchControlPoints();
    for (size_t i = 0; i + 80 <= points.size(); i += 80)
      for (size_t k = 0; k < 10; ++k)
        for (int a = 0; a < 3; ++a) points[i + 4 * k + a] += origin_[a];
    return points;
  }
  std::optional<PatchVertices> patchVertices() const override {
    std::optional<PatchVertices> patches = local_->patchVertices();
    if (patches)
      for (size_t i = 0; i < patches->position.size(); ++i) patches->position[i] += origin_[i % 3];
    return patches;
  }
  void precompute(Timings& timings) override { local_->precompute(timings); }
  DeformSession* session() override { return local_->session(); }

 private:
  std::unique_ptr<MethodRun> local_;
  glm::dvec3 origin_;
};

}  // namespace

std::unique_ptr<MethodRun> inLocalFrame(std::unique_ptr<MethodRun> local, glm::dvec3 origin) {
  if (origin == glm::dvec3(0.0)) return local;
  return std::make_unique<LocalFrameRun>(std::move(local), origin);
}

}  // namespace sffd
