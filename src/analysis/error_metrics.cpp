#include "analysis/error_metrics.h"

#include <algorithm>
#include <cmath>

#include "model/bicubic_patch.h"
#include "kernels/clip/knot_box_clip.h"
#include "kernels/common/lattice_eval.h"
#include "model/mesh_topology.h"

namespace sffd {
namespace {

double angleDeg(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * (180.0 / M_PI);
}

}  // namespace

ErrorStats errorStats(const std::vector<double>& values) {
  ErrorStats s;
  if (values.empty()) return s;
  double sum = 0;
  for (double v : values) {
    sum += v;
    s.max = std::max(s.max, v);
  }
  s.avg = sum / double(values.size());
  double sq = 0;
  for (double v : values) sq += (v - s.avg) * (v - s.avg);
  s.std = std::sqrt(sq / double(values.size()));
  return s;
}

ExactReference::ExactReference(const Mesh& input, const PackedLattice& lattice) : mesh_(input), lattice_(lattice) {
  bpt_ = !input.patches.empty() && input.vertexPatch.size() == input.positions.size() &&
         input.vertexUV.size() == input.positions.size();
}

void ExactReference::preImage(uint32_t parent, const glm::dvec3& lam, glm::dvec3& x, glm::dvec3& n) const {
  const auto& t = mesh_.triangles[parent];
  if (bpt_) {
    const uint32_t p = mesh_.vertexPatch[t[0]];
    if (mesh_.vertexPatch[t[1]] == p && mesh_.vertexPatch[t[2]] == p && p < mesh_.patches.size()) {
      glm::dvec2 uv = lam.x * mesh_.vertexUV[t[0]] + lam.y * mesh_.vertexUV[t[1]] + lam.z * mesh_.vertexUV[t[2]];
      uv = glm::clamp(uv, glm::dvec2(0.0), glm::dvec2(1.0));
      glm::dvec3 Su, Sv;
      evaluateBicubic(mesh_.patches[p], uv.x, uv.y, x, Su, Sv);
      n = bicubicNormal(mesh_.patches[p], uv.x, uv.y);
      return;
    }
  }
  const glm::dvec3 &V0 = mesh_.positions[t[0]], &V1 = mesh_.positions[t[1]], &V2 = mesh_.positions[t[2]];
  x = (lam.x * V0 + lam.y * V1) + lam.z * V2;
  glm::dvec3 s = lam.x * mesh_.normals[t[0]] + lam.y * mesh_.normals[t[1]] + lam.z * mesh_.normals[t[2]];
  if (!(glm::length(s) > 0)) s = glm::cross(V1 - V0, V2 - V0);
  n = glm::length(s) > 0 ? glm::normalize(s) : glm::dvec3(0, 0, 1);
}

void ExactReference::deform(const glm::dvec3& x, const glm::dvec3& n, glm::dvec3& xr, glm::dvec3& nr) const {
  LatticeEvaluator<double> eval(lattice_.params, lattice_.frame, lattice_.coeffs);
  LatticeSampleT<double> S = eval.evaluate(RVec3<double>::from(x));
  if (!S.inside && lattice_.params.degree.w == SFFD_OUTSIDE_KEEP) {
    xr = x;
    nr = n;
    return;
  }
  xr = S.value.glm();
  glm::dvec3 c = eval.cofactorNormal(S, RVec3<double>::from(n)).glm();
  nr = glm::length(c) > 0 ? glm::normalize(c) : n;
}

ErrorReport measureErrors(const Mesh& input, const PackedLattice& lattice, const PatchVertices& result) {
  ErrorReport rep;
  ExactReference ref(input, lattice);
  const size_t nv = size_t(tessVertexCount(result.level));
  const size_t total = result.vertexCount();
  std::vector<double> geo, nrm;
  geo.reserve(total), nrm.reserve(total);
  for (size_t g = 0; g < total; ++g) {
    const uint32_t parent = result.parent[g / nv];
    // A parent without area (two corners at one position) has no part in the result (patch_output.h).
    if (!input.weldId.empty() && weldDegenerate(input, input.triangles[parent])) continue;
    glm::dvec3 lam(result.lamParent[3 * g], result.lamParent[3 * g + 1], result.lamParent[3 * g + 2]);
    glm::dvec3 x, n, xr, nr;
    ref.preImage(parent, lam, x, n);
    ref.deform(x, n, xr, nr);
    glm::dvec3 p(result.position[3 * g], result.position[3 * g + 1], result.position[3 * g + 2]);
    glm::dvec3 q(result.normal[3 * g], result.normal[3 * g + 1], result.normal[3 * g + 2]);
    geo.push_back(glm::length(p - xr));
    nrm.push_back(angleDeg(q, nr));
  }
  rep.vertices = geo.size();
  rep.geometry = errorStats(geo);
  rep.normalDeg = errorStats(nrm);
  return rep;
}

PatchVertices linearPatchVertices(const Mesh& output, int level) {
  PatchVertices pv;
  pv.level = level;
  const int L = level, nv = tessVertexCount(L);
  const size_t nt = output.triangles.size();
  pv.parent.resize(nt);
  pv.lamParent.resize(nt * nv * 3);
  pv.position.resize(nt * nv * 3);
  pv.normal.resize(nt * nv * 3);
  for (size_t t = 0; t < nt; ++t) {
    pv.parent[t] = uint32_t(t);
    const auto& tri = output.triangles[t];
    for (int r = 0; r <= L; ++r)
      for (int q = 0; q <= r; ++q) {
        const size_t g = t * nv + r * (r + 1) / 2 + q;
        const glm::dvec3 lam(double(L - r) / L, double(r - q) / L, double(q) / L);
        glm::dvec3 p = lam.x * output.positions[tri[0]] + lam.y * output.positions[tri[1]] + lam.z * output.positions[tri[2]];
        glm::dvec3 n = lam.x * output.normals[tri[0]] + lam.y * output.normals[tri[1]] + lam.z * output.normals[tri[2]];
        n = glm::length(n) > 0 ? glm::normalize(n) : n;
        for (int a = 0; a < 3; ++a) {
          pv.lamParent[3 * g + a] = lam[a];
          pv.position[3 * g + a] = p[a];
          pv.normal[3 * g + a] = n[a];
        }
      }
  }
  return pv;
}

double signedVolume(const Mesh& mesh, const LocalFrame& frame) {
  if (mesh.positions.empty()) return 0;
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const auto& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  // About the box's centre, in the frame's units (its origin then plays no part).
  const glm::dvec3 c = 0.5 * (lo + hi);
  auto at = [&](uint32_t v) { return (mesh.positions[v] - c) * frame.scale; };
  double v = 0;
  for (const auto& t : mesh.triangles) v += glm::dot(at(t[0]), glm::cross(at(t[1]), at(t[2])));
  return v / 6;
}

bool isClosed(const Mesh& mesh) {
  if (mesh.triangles.empty()) return false;
  MeshTopology t = buildTopology(mesh);
  return t.boundaryEdges == 0 && t.nonManifoldEdges == 0;
}

void gaussLegendre01(int q, std::vector<double>& nodes, std::vector<double>& weights) {
  nodes.assign(q, 0.0);
  weights.assign(q, 0.0);
  for (int i = 0; i < q; ++i) {
    // Newton's method on P_q from Chebyshev-like initial guesses on [-1, 1].
    double x = std::cos(M_PI * (i + 0.75) / (q + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= q; ++k) {
        double p2 = ((2.0 * k - 1) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (q == 1) p1 = x, p0 = 1;
      dp = q * (x * p1 - p0) / (x * x - 1);
      double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= q; ++k) {
        double p2 = ((2.0 * k - 1) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = q * (x * p1 - p0) / (x * x - 1);
    }
    nodes[i] = 0.5 * (1 - x);
    weights[i] = 1.0 / ((1 - x * x) * dp * dp);   // 2/((1-x^2) P'^2) on [-1,1], halved for [0,1]
  }
}

double exactDeformedVolume(const Mesh& input, const Lattice& lattice, int quadraturePoints) {
  const PackedLattice P = packLattice(lattice);
  LatticeEvaluator<double> eval(P.params, P.frame, P.coeffs);
  const bool keep = P.params.degree.w == SFFD_OUTSIDE_KEEP;
  const int n = lattice.degree[0] + lattice.degree[1] + lattice.degree[2];
  // Integrand R . cof(J) n: degree 3n - 2 in the barycentrics; with the Duffy factor (1 - u) the rule
  // needs 2q - 1 >= 3n - 1 points per direction.
  const int q = quadraturePoints > 0 ? quadraturePoints : (3 * n - 2 + 3) / 2;
  std::vector<double> nodes, weights;
  gaussLegendre01(q, nodes, weights);
  std::vector<glm::dvec3> lams;   // (l0, l1, l2) of the rule
  std::vector<double> w;
  for (int i = 0; i < q; ++i)
    for (int j = 0; j < q; ++j) {
      const double l1 = nodes[i], l2 = nodes[j] * (1 - nodes[i]);
      lams.push_back({1 - l1 - l2, l1, l2});
      w.push_back(weights[i] * weights[j] * (1 - nodes[i]));
    }

  double total = 0;
  for (const SubTriangle& T : clipAgainstKnotBoxes(input, lattice)) {
    const auto& tri = input.triangles[T.parent];
    const glm::dvec3 &V0 = input.positions[tri[0]], &V1 = input.positions[tri[1]], &V2 = input.positions[tri[2]];
    const glm::dvec3 aP = glm::cross(V1 - V0, V2 - V0);   // twice the parent's area, times its unit normal
    const double twiceArea = glm::length(aP);
    if (!(twiceArea > 0)) continue;
    const glm::dvec3 nu = aP / twiceArea;
    // The sub-triangle's share of the parent's area: the determinant of its corners' barycentrics.
    const glm::dvec3 &a = T.corners[0].lam, &b = T.corners[1].lam, &c = T.corners[2].lam;
    const double detLam = glm::dot(a, glm::cross(b, c));
    glm::dvec3 x[3];
    for (int k = 0; k < 3; ++k) x[k] = (T.corners[k].lam.x * V0 + T.corners[k].lam.y * V1) + T.corners[k].lam.z * V2;
    double acc = 0;
    for (size_t k = 0; k < lams.size(); ++k) {
      const glm::dvec3 p = lams[k].x * x[0] + lams[k].y * x[1] + lams[k].z * x[2];
      LatticeSampleT<double> S = eval.evaluate(RVec3<double>::from(p));
      glm::dvec3 R, cn;
      if (!S.inside && keep) {
        R = p;
        cn = nu;
      } else {
        R = S.value.glm();
        cn = eval.cofactorNormal(S, RVec3<double>::from(nu)).glm() / (S.h.x * S.h.y * S.h.z);
      }
      acc += w[k] * glm::dot(R, cn);
    }
    total += acc * twiceArea * detLam;
  }
  return total / 3;
}

namespace {
VolumeError volumeError(double reference, double result) {
  return {reference, result, reference != 0 ? std::abs(result - reference) / std::abs(reference) : std::abs(result)};
}
}  // namespace

std::optional<VolumeError> measureVolume(const Mesh& input, const Lattice& lattice, const Mesh& output) {
  if (!isClosed(input)) return std::nullopt;
  return volumeError(exactDeformedVolume(input, lattice), signedVolume(output));
}

ErrorReport measureErrorsInFrame(const Mesh& input, const Lattice& lattice, PatchVertices result, const Mesh& output,
                                 const LocalFrame& frame) {
  if (frame.isWorld()) {
    ErrorReport report = measureErrors(input, packLattice(lattice), result);
    report.volume = measureVolume(input, lattice, output);
    return report;
  }
  const Mesh localInput = localMesh(input, frame);
  const Lattice local = localLattice(lattice, frame);
  for (size_t i = 0; i + 3 <= result.position.size(); i += 3) {
    double* p = &result.position[i];
    const glm::dvec3 local = frame.toLocal({p[0], p[1], p[2]});
    p[0] = local.x, p[1] = local.y, p[2] = local.z;
  }
  ErrorReport report = measureErrors(localInput, packLattice(local), result);
  for (double* length : {&report.geometry.avg, &report.geometry.max, &report.geometry.std}) *length /= frame.scale;
  if (isClosed(localInput)) {   // the output's volume in the frame's units too, without a copy of it
    report.volume = volumeError(exactDeformedVolume(localInput, local), signedVolume(output, frame));
    const double cube = frame.scale * frame.scale * frame.scale;   // a power of two: exact
    report.volume->reference /= cube;
    report.volume->result /= cube;
  }
  return report;
}

}  // namespace sffd
