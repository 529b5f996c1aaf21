// Deformer: every method computes in coordinates local to the lattice box (docs/ROBUSTNESS.md
// "Models far from the origin" and "Models of any size"). The mesh and the lattice are moved, and scaled by
// a power of two, on the host in double before anything reaches a device, and the results moved back in
// double, so float kernels keep their precision relative to the model's size wherever the model sits,
// and their thresholds (a squared length below float's smallest normal number has no direction, as do
// products of six lengths past float's range) meet every size as they meet size 1. A scale by a power of
// two is exact, so a model 2^k times as large gives 2^k times the result, bit for bit. Strict results stay
// identical across backends: they all see the same local inputs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include <sffd/error.h>

#include "pipelines/deformer_internal.h"

namespace sffd {

namespace {
// `centre` rounded to a multiple of a power of two 8 to 16 times `extent`: 0 within about 4 extents
// of 0 (the computation then runs on the input's own bits, as before), else within 8 extents of it.
double roundedOrigin(double centre, double extent) {
  const double step = std::ldexp(1.0, std::ilogb(extent) + 4);
  return std::round(centre / step) * step;
}

// The power of two that brings `extent` into [1, 2), or 1 for an extent of a usual size: the kernels'
// thresholds changed the result of a box below about 1e-6 (2^-20) and above about 1e6 (2^20) units
// across, whatever the edge length (docs/ROBUSTNESS.md "Models of any size"); the band [2^-8, 2^12)
// keeps a margin of 2^12 below and 2^8 above, and keeps the results of usual models as they were.
double unitScale(double extent) {
  if (!(extent > 0) || !std::isfinite(extent)) return 1;
  // Below double's smallest normal number the box has lost bits already, and 2^-e would pass double's range.
  if (extent < std::numeric_limits<double>::min()) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", extent);
    throw Error(ErrorKind::Input, std::string("the lattice's box is ") + text +
                                      " across, below the smallest normal double (2.2e-308): too small to compute in");
  }
  const int e = std::ilogb(extent);
  return e >= kLocalScaleMinExponent && e < kLocalScaleMaxExponent ? 1 : std::ldexp(1.0, -e);
}
}  // namespace

LocalFrame latticeLocalFrame(const Lattice& lattice) {
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
  LocalFrame frame;
  for (int a = 0; a < 3; ++a) frame.origin[a] = roundedOrigin(0.5 * (lo[a] + hi[a]), extent);
  frame.scale = unitScale(extent);
  return frame;
}

Lattice localLattice(Lattice lattice, const LocalFrame& frame) {
  // World: x = x' / s + origin, so p = F x + o = (F / s) x' + (o + F origin). Parameters too (a native
  // lattice's knots are world coordinates, as small or large as the model): p' = (p - q) t, with q the
  // domain's centre rounded and t the power of two that brings the domain to a usual size, so the
  // kernels' parameters are as small as the box and of size 1; knots - q is exact (Sterbenz) for a box
  // far from 0, and the scales are exact.
  const double s = frame.scale;
  glm::dvec3 q(0.0), t(1.0);
  for (int a = 0; a < 3; ++a) {
    const double extent = lattice.domainHi(a) - lattice.domainLo(a);
    q[a] = roundedOrigin(0.5 * (lattice.domainLo(a) + lattice.domainHi(a)), extent);
    t[a] = unitScale(extent);
  }
  for (glm::dvec3& p : lattice.controlPoints) p = frame.toLocal(p);
  lattice.frameOffset = (lattice.frameOffset + lattice.frameLinear * frame.origin - q) * t;
  for (int c = 0; c < 3; ++c)
    for (int a = 0; a < 3; ++a) lattice.frameLinear[c][a] *= t[a] / s;   // glm: [column][row]; row a is axis a
  for (int a = 0; a < 3; ++a)
    for (double& k : lattice.knots[a]) k = (k - q[a]) * t[a];
  return lattice;
}

Mesh localMesh(Mesh mesh, const LocalFrame& frame) {
  for (glm::dvec3& p : mesh.positions) p = frame.toLocal(p);
  for (BicubicPatch& patch : mesh.patches)
    for (glm::dvec3& p : patch.points) p = frame.toLocal(p);
  return mesh;
}

Mesh worldMesh(Mesh mesh, const LocalFrame& frame) {
  for (glm::dvec3& p : mesh.positions) p = frame.toWorld(p);
  for (BicubicPatch& patch : mesh.patches)
    for (glm::dvec3& p : patch.points) p = frame.toWorld(p);
  return mesh;
}

namespace {

// Hands each piece to `to` with its positions in world coordinates (as worldMesh).
class WorldSink final : public MeshSink {
 public:
  WorldSink(MeshSink& to, const LocalFrame& frame) : to_(to), frame_(frame) {}
  void begin(const Mesh& tables) override { to_.begin(tables); }
  void add(const Mesh& piece, size_t firstVertex) override {
    moved_ = piece;
    for (glm::dvec3& p : moved_.positions) p = frame_.toWorld(p);
    to_.add(moved_, firstVertex);
  }
  void end() override { to_.end(); }

 private:
  MeshSink& to_;
  LocalFrame frame_;
  Mesh moved_;
};

// A method run on local inputs whose results are handed out in world coordinates (except
// deviceOutput(), which stays on the device in local coordinates: Deformer::localOrigin(), localScale()).
// Normals and the normal patches are directions, the same in both frames.
class LocalFrameRun final : public MethodRun {
 public:
  LocalFrameRun(std::unique_ptr<MethodRun> local, const LocalFrame& frame) : local_(std::move(local)), frame_(frame) {}

  void deform(const Lattice& lattice, Timings& timings, const ProgressReporter& progress) override {
    local_->deform(localLattice(lattice, frame_), timings, progress);
  }
  Mesh result(const ProgressReporter& progress) const override { return worldMesh(local_->result(progress), frame_); }
  void streamResult(MeshSink& sink, const ProgressReporter& progress) const override {
    WorldSink moved(sink, frame_);
    local_->streamResult(moved, progress);
  }
  std::vector<OutputChunk> deviceOutput() const override { return local_->deviceOutput(); }
  size_t subTriangles() const override { return local_->subTriangles(); }
  std::vector<double> patchControlPoints() const override {
    // 20 points (x, y, z, 0) a sub-triangle: 10 of the geometry patch (moved), 10 of the normals.
    std::vector<double> points = local_->patchControlPoints();
    for (size_t i = 0; i + 80 <= points.size(); i += 80)
      for (size_t k = 0; k < 10; ++k) {
        double* p = &points[i + 4 * k];
        const glm::dvec3 world = frame_.toWorld({p[0], p[1], p[2]});
        for (int a = 0; a < 3; ++a) p[a] = world[a];
      }
    return points;
  }
  std::optional<PatchVertices> patchVertices() const override {
    std::optional<PatchVertices> patches = local_->patchVertices();
    if (patches)
      for (size_t i = 0; i + 3 <= patches->position.size(); i += 3) {
        double* p = &patches->position[i];
        const glm::dvec3 world = frame_.toWorld({p[0], p[1], p[2]});
        p[0] = world.x, p[1] = world.y, p[2] = world.z;
      }
    return patches;
  }
  void precompute(Timings& timings) override { local_->precompute(timings); }
  DeformSession* session() override { return local_->session(); }

 private:
  std::unique_ptr<MethodRun> local_;
  LocalFrame frame_;
};

}  // namespace

std::unique_ptr<MethodRun> inLocalFrame(std::unique_ptr<MethodRun> local, const LocalFrame& frame) {
  if (frame.isWorld()) return local;
  return std::make_unique<LocalFrameRun>(std::move(local), frame);
}

}  // namespace sffd
