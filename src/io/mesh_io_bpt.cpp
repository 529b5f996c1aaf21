// .bpt Bezier patch files (METHOD.md 5, "Utah teapot"): a patch count, then per patch a line "3 3"
// (the degrees) and 16 control points "x y z", P(u,v) = sum_r sum_c B3_r(u) B3_c(v) P[4r+c].
//
// Tessellation: each patch is sampled on a uniform (res+1) x (res+1) grid of (u, v) (res =
// MeshReadOptions::bptResolution): vertex (i, j) of patch p is vertex p*(res+1)^2 + i*(res+1) + j at
// u = i/res, v = j/res, with vertexPatch = p and vertexUV = (u, v). Each grid cell gives the triangles
// (i,j)(i+1,j)(i,j+1) and (i+1,j)(i+1,j+1)(i,j+1): counter-clockwise seen from Su x Sv, 2 res^2 a patch.
// The cell is split along its diagonal (i+1,j)-(i,j+1), where u grows as v falls, as the reference
// implementation's reader does (acaffd mvc_model/model.py, parse_from_bpt: triangles (i1,i2,i3) and
// (i3,i2,i4)); that diagonal is the same whether or not the patch is transposed (below). The choice
// matters to the error figures: the reference (u, v) is interpolated linearly over each triangle, and
// at a collapsed patch edge the fan triangles' apex corner carries the other grid vertex's v.
// The normal is the exact Su x Sv; where it vanishes (a collapsed patch edge: the lid apex, the bottom
// centre) it is taken at a parameter nudged toward the patch interior.
// Orientation: when the tessellation's signed volume (about its box centre) is negative, i.e. Su x Sv
// points inward as it does for acaffd's t.bpt, every patch is stored transposed (points[4r+c] <->
// points[4c+r], u and v swapped) so that Su x Sv of the stored patches points outward. `patches`,
// vertexUV and the normals always agree with each other under the formula above.
//
// Welding: every patch keeps its own vertices (so that each triangle's vertices carry (u, v) of one
// patch), but vertices of different patches whose positions agree within 1e-9 of the bounding box
// diagonal are snapped to one position and so share a weldId. Where all the normals at one welded
// position agree within 1e-3 rad (a smooth seam, or the nudged normals at a collapsed point) they are
// replaced by their normalised mean, so the seam reads as smooth; a real crease keeps its split normals.
// Degenerate triangles at collapsed edges are kept (7200 triangles for the 36-patch teapot at res 10).
// normalsFromFile is true: the normals are the surface's exact ones, not estimated from triangles.
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "model/bicubic_patch.h"
#include <sffd/error.h>
#include "io/io_util.h"
#include "io/mesh_io_internal.h"

namespace sffd::meshio {
namespace {

void tessellate(Mesh& mesh, int res) {
  const size_t perPatch = size_t(res + 1) * size_t(res + 1);
  const size_t nVert = mesh.patches.size() * perPatch;
  mesh.positions.resize(nVert);
  mesh.normals.resize(nVert);
  mesh.vertexPatch.resize(nVert);
  mesh.vertexUV.resize(nVert);
  mesh.triangles.clear();
  mesh.triangles.reserve(mesh.patches.size() * 2 * size_t(res) * size_t(res));
  for (size_t p = 0; p < mesh.patches.size(); ++p) {
    const BicubicPatch& P = mesh.patches[p];
    const size_t base = p * perPatch;
    for (int i = 0; i <= res; ++i)
      for (int j = 0; j <= res; ++j) {
        double u = double(i) / res, v = double(j) / res;
        size_t vid = base + size_t(i) * (res + 1) + j;
        glm::dvec3 S, Su, Sv;
        evaluateBicubic(P, u, v, S, Su, Sv);
        mesh.positions[vid] = S;
        mesh.normals[vid] = bicubicNormal(P, u, v);
        mesh.vertexPatch[vid] = uint32_t(p);
        mesh.vertexUV[vid] = {u, v};
      }
    for (int i = 0; i < res; ++i)
      for (int j = 0; j < res; ++j) {
        uint32_t a = uint32_t(base + size_t(i) * (res + 1) + j);
        uint32_t b = a + uint32_t(res + 1), c = b + 1, d = a + 1;
        mesh.triangles.push_back({a, b, d});
        mesh.triangles.push_back({b, c, d});
      }
  }
}

// Signed volume enclosed by the triangles, about the centre of their box.
double signedVolume(const Mesh& mesh) {
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const auto& q : mesh.positions) {
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  glm::dvec3 c = 0.5 * (lo + hi);
  double v = 0;
  for (const auto& t : mesh.triangles)
    v += glm::dot(mesh.positions[t[0]] - c, glm::cross(mesh.positions[t[1]] - c, mesh.positions[t[2]] - c));
  return v / 6;
}

struct CellHash {
  size_t operator()(const std::array<int64_t, 3>& c) const {
    uint64_t h = uint64_t(c[0]) * 0x9E3779B97F4A7C15ull;
    h ^= uint64_t(c[1]) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= uint64_t(c[2]) + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
    return size_t(h);
  }
};

}  // namespace

Mesh readBpt(const std::string& path, const std::string& text, const MeshReadOptions& options) {
  const int res = options.bptResolution;
  if (res < 1 || res > 1000) throw inputError(path, 0, "bpt resolution must be 1..1000, not " + std::to_string(res));
  io::Tokenizer tz(text);
  std::string_view t;
  size_t line = 1;
  if (!tz.next(t, line)) throw inputError(path, 0, "empty file");
  long long count = 0;
  if (!io::parseInt(t, count) || count < 1) throw inputError(path, line, "bad patch count " + io::quoted(t));
  // A patch takes at least 4 + 16 * 6 bytes of text.
  if (uint64_t(count) > text.size() / 100 + 1)
    throw inputError(path, line, "the file declares " + std::to_string(count) + " patches, more than it can hold (truncated?)");
  const uint64_t perPatch = uint64_t(res + 1) * uint64_t(res + 1);
  if (uint64_t(count) * perPatch > kMaxVertices) throw inputError(path, line, "too many vertices at this resolution");

  Mesh mesh;
  mesh.patches.resize(size_t(count));
  for (long long p = 0; p < count; ++p) {
    for (int d = 0; d < 2; ++d) {
      if (!tz.next(t, line))
        throw inputError(path, line, "file ends in patch " + std::to_string(p + 1) + " of " + std::to_string(count));
      long long deg = 0;
      if (!io::parseInt(t, deg)) throw inputError(path, line, "bad patch degree " + io::quoted(t) + " (expected '3 3')");
      if (deg != 3) throw inputError(path, line, "patch degree " + std::to_string(deg) + ": only bicubic ('3 3') patches are supported");
    }
    for (int k = 0; k < 48; ++k) {
      if (!tz.next(t, line))
        throw inputError(path, line, "file ends in patch " + std::to_string(p + 1) + " of " + std::to_string(count));
      double x = 0;
      if (!io::parseDouble(t, x)) throw inputError(path, line, "bad number " + io::quoted(t));
      if (!std::isfinite(x)) throw inputError(path, line, "non-finite coordinate " + io::quoted(t));
      mesh.patches[size_t(p)].points[size_t(k / 3)][k % 3] = x;
    }
  }
  if (tz.next(t, line)) throw inputError(path, line, "unexpected " + io::quoted(t) + " after the last patch");

  // Sample; if the surface faces inward (negative signed volume about its box centre), transpose every
  // patch (swap u and v) and sample again, so that Su x Sv points outward.
  tessellate(mesh, res);
  if (signedVolume(mesh) < 0) {
    for (BicubicPatch& P : mesh.patches) {
      BicubicPatch T;
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) T.points[4 * c + r] = P.points[4 * r + c];
      P = T;
    }
    tessellate(mesh, res);
  }
  const size_t nVert = mesh.positions.size();
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const auto& q : mesh.positions) {
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }

  // Weld positions within tol (snap each to the first representative found within reach).
  const double tol = 1e-9 * glm::length(hi - lo);
  if (tol > 0) {
    std::unordered_map<std::array<int64_t, 3>, std::vector<uint32_t>, CellHash> cells;
    cells.reserve(nVert);
    auto cellOf = [&](const glm::dvec3& q) {
      return std::array<int64_t, 3>{int64_t(std::floor(q.x / tol)), int64_t(std::floor(q.y / tol)), int64_t(std::floor(q.z / tol))};
    };
    for (size_t v = 0; v < nVert; ++v) {
      glm::dvec3& q = mesh.positions[v];
      auto c = cellOf(q);
      bool snapped = false;
      for (int dx = -1; dx <= 1 && !snapped; ++dx)
        for (int dy = -1; dy <= 1 && !snapped; ++dy)
          for (int dz = -1; dz <= 1 && !snapped; ++dz) {
            auto it = cells.find({c[0] + dx, c[1] + dy, c[2] + dz});
            if (it == cells.end()) continue;
            for (uint32_t r : it->second)
              if (glm::length(mesh.positions[r] - q) <= tol) {
                q = mesh.positions[r];
                snapped = true;
                break;
              }
          }
      if (!snapped) cells[c].push_back(uint32_t(v));
    }
  }
  weldPositions(mesh);

  // Smooth seams: one normal per welded position where all agree within 1e-3 rad.
  {
    size_t groups = 0;
    for (uint32_t w : mesh.weldId) groups = std::max<size_t>(groups, w + 1);
    std::vector<glm::dvec3> sum(groups, glm::dvec3(0.0));
    std::vector<uint32_t> members(groups, 0);
    for (size_t v = 0; v < nVert; ++v) {
      sum[mesh.weldId[v]] += mesh.normals[v];
      ++members[mesh.weldId[v]];
    }
    std::vector<uint8_t> smooth(groups, 1);
    std::vector<glm::dvec3> mean(groups);
    for (size_t g = 0; g < groups; ++g) {
      double len = glm::length(sum[g]);
      mean[g] = len > 0 ? sum[g] / len : glm::dvec3(0, 0, 1);
      if (!(len > 0)) smooth[g] = 0;
    }
    const double cosTol = std::cos(1e-3);
    for (size_t v = 0; v < nVert; ++v)
      if (glm::dot(mesh.normals[v], mean[mesh.weldId[v]]) < cosTol) smooth[mesh.weldId[v]] = 0;
    for (size_t v = 0; v < nVert; ++v)
      if (members[mesh.weldId[v]] > 1 && smooth[mesh.weldId[v]]) mesh.normals[v] = mean[mesh.weldId[v]];
  }
  mesh.normalsFromFile = true;
  return mesh;
}

}  // namespace sffd::meshio
