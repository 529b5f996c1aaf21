#include "core/job_budget.h"

#include <algorithm>
#include <charconv>
#include <cctype>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <unistd.h>

#include <sffd/error.h>
#include "kernels/common/shader_layout.h"

namespace sffd {

void checkSizeOptions(const std::optional<std::string>& edgeLength, const std::optional<std::string>& tess) {
  if (edgeLength) {
    double l = 0;
    const std::string& s = *edgeLength;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), l);
    if (ec != std::errc() || p != s.data() + s.size() || !std::isfinite(l) || !(l > 0))
      throw Error(ErrorKind::Input, "--edge-length must be a finite length > 0 in model units, not '" + s + "'");
  }
  if (tess) {
    long long n = 0;
    const std::string& s = *tess;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), n);
    bool integer = p == s.data() + s.size() && !s.empty() && (ec == std::errc() || ec == std::errc::result_out_of_range);
    if (!integer || ec != std::errc() || n < 1 || n > kMaxTessLevel)
      throw Error(ErrorKind::Input, "--tess must be an integer 1.." + std::to_string(kMaxTessLevel) + ", not '" + s +
                                        "' (level N makes N^2 triangles a patch)");
  }
}

namespace {

uint64_t meshBytes(const Mesh& m, bool withPatches) {
  uint64_t b = m.positions.size() * sizeof(glm::dvec3) + m.normals.size() * sizeof(glm::dvec3) +
               m.weldId.size() * sizeof(uint32_t) + m.triangles.size() * sizeof(m.triangles[0]);
  if (withPatches)
    b += m.patches.size() * sizeof(BicubicPatch) + m.vertexPatch.size() * sizeof(uint32_t) + m.vertexUV.size() * sizeof(glm::dvec2);
  return b;
}

}  // namespace

uint64_t meshHeldBytes(const Mesh& m) {
  auto held = [](const auto& v) { return uint64_t(v.capacity()) * sizeof(v[0]); };
  return held(m.positions) + held(m.normals) + held(m.weldId) + held(m.triangles) + held(m.patches) + held(m.vertexPatch) +
         held(m.vertexUV) + held(m.texcoords) + held(m.colors) + held(m.triangleMaterial) + held(m.triangleGroup);
}

uint64_t parseByteSize(const char* s) {
  char* end = nullptr;
  double v = std::strtod(s, &end);
  if (end == s || !std::isfinite(v) || v <= 0) return 0;
  double f = 1;
  switch (std::toupper(static_cast<unsigned char>(*end))) {
    case 'K': f = 1024.0; ++end; break;
    case 'M': f = 1024.0 * 1024; ++end; break;
    case 'G': f = 1024.0 * 1024 * 1024; ++end; break;
    case 'T': f = 1024.0 * 1024 * 1024 * 1024; ++end; break;
    default: break;
  }
  if (*end == 'B' || *end == 'b') ++end;
  if (*end != '\0') return 0;
  double bytes = v * f;
  return bytes >= 1.8e19 ? UINT64_MAX : uint64_t(bytes);
}

double estimateSubTriangles(const Mesh& mesh, double l) {
  // The area in units of l^2, the edges divided by l first: the products of a mesh 1e-200 or 1e200 across
  // stay within double's range, and the estimate does not depend on the model's size.
  double area = 0;
  for (const auto& t : mesh.triangles) {
    const glm::dvec3 c = glm::cross((mesh.positions[t[1]] - mesh.positions[t[0]]) / l, (mesh.positions[t[2]] - mesh.positions[t[0]]) / l);
    area += 0.5 * std::hypot(c.x, c.y, c.z);
  }
  return area / (std::sqrt(3.0) / 4) + double(mesh.triangles.size());
}

double defaultEdgeLength(const Mesh& mesh) {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const glm::dvec3& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const double l = 0.1 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  // Every vertex at one point, or none (an empty mesh, l = -inf): no size to take a tenth of, and no edge to
  // split: any length gives the same result (0 made smooth FFD of an empty mesh ask for an --edge-length).
  return l > 0 ? l : 1.0;
}

void checkSubTriangleCount(const Mesh& mesh, double l, const std::string& name) {
  if (!(l > 0) || !std::isfinite(l)) throw Error(ErrorKind::Input, name + " must be a positive number");
  const double estimate = estimateSubTriangles(mesh, l);
  if (!(estimate <= kMaxSubTriangles)) {   // NaN too: edges past double's range over l make inf - inf
    char buf[160];
    if (std::isfinite(estimate))
      std::snprintf(buf, sizeof buf, " %g would make about %.3g sub-triangles, above the limit of %.3g", l, estimate, kMaxSubTriangles);
    else
      std::snprintf(buf, sizeof buf, " %g would make more sub-triangles than a double counts, above the limit of %.3g", l, kMaxSubTriangles);
    throw Error(ErrorKind::Input, name + buf);
  }
}

std::string formatBytes(uint64_t bytes) {
  static const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
  double v = double(bytes);
  int u = 0;
  while (v >= 1024 && u < 4) v /= 1024, ++u;
  char buf[64];
  if (u == 0) std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(bytes));
  else std::snprintf(buf, sizeof buf, "%.2f %s", v, units[u]);
  return buf;
}

JobEstimate estimateClassicJob(const Mesh& mesh, const PackedLattice& P, size_t realBytes, const DeviceLimits* limits) {
  JobEstimate e;
  const uint64_t n = mesh.positions.size();
  const uint64_t vertexBytes = 4 * uint64_t(realBytes);
  e.chunkVertices = std::max<uint64_t>(n, 1);
  if (limits) {   // as classicFfdGpu chunks
    uint64_t byRange = limits->maxStorageBufferRange / vertexBytes;
    uint64_t byGroups = uint64_t(limits->maxWorkGroupCount[0]) * limits->maxWorkGroupCount[1] * SFFD_LOCAL_SIZE;
    e.chunkVertices = std::max<uint64_t>(1, std::min({byRange, byGroups, e.chunkVertices}));
  }
  e.chunks = (n + e.chunkVertices - 1) / e.chunkVertices;
  const uint64_t lattice = (P.coeffs.size() + P.frame.size()) * uint64_t(realBytes);
  uint64_t host = meshBytes(mesh, true)          // the input, held to the end
                  + 8 * sizeof(double) * n       // ClassicOutput: positions and normals, 4 doubles each
                  + meshBytes(mesh, false)       // the deformed copy written out
                  + 76 * n                       // the writer's distinct-position index (hash node + bucket + id)
                  + lattice                      // the coefficients converted to the kernel's real type
                  + (1u << 20);                  // the writer's buffer
  if (limits) {
    host += 2 * vertexBytes * e.chunkVertices;    // upload/download staging of one chunk
    e.deviceBytes = lattice + 4 * vertexBytes * n;   // every chunk's inputs and outputs stay on the device
  }
  e.hostBytes = host;
  return e;
}

uint64_t hostMemoryLimit(uint64_t requested) {
  if (requested) return requested;
  uint64_t limit = 0;
  long pages = ::sysconf(_SC_PHYS_PAGES), pageSize = ::sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && pageSize > 0) limit = uint64_t(pages) * uint64_t(pageSize);
  // A container's memory limit (cgroup v2, then v1) when it is lower.
  for (const char* f : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(f);
    std::string text;
    if (!(in >> text) || text == "max") continue;
    uint64_t v = parseByteSize(text.c_str());
    if (v > 0 && (limit == 0 || v < limit)) limit = v;
  }
  return limit;
}

uint64_t estimateLatticeBytes(const Lattice& L) {
  double boxes = 1, perBox = 1, points = 1;
  for (int a = 0; a < 3; ++a) {
    // Knot boxes: the distinct knot values in the domain, less one (counts - degree when uniform).
    double distinct = 0, last = 0;
    const auto& k = L.knots[a];
    for (size_t i = size_t(L.degree[a]); i <= size_t(L.counts[a]) && i < k.size(); ++i)
      if (distinct == 0 || k[i] != last) ++distinct, last = k[i];
    boxes *= k.empty() ? double(L.counts[a] - L.degree[a]) : std::max(1.0, distinct - 1);
    perBox *= L.degree[a] + 1;
    points *= L.counts[a];
  }
  const double coeffs = boxes * perBox;
  // Points (dvec3), the box form (dvec3), the packed form (4 doubles) and its kernel copy (4 doubles at
  // most): all alive at once while a method uploads the lattice.
  const double bytes = points * 24 + coeffs * (24 + 32 + 32);
  return bytes >= 1.8e19 ? UINT64_MAX : uint64_t(bytes);
}

namespace {

std::string limitText(uint64_t limit, uint64_t memoryLimit, const char* limitName) {
  return formatBytes(limit) + (memoryLimit ? " (" + std::string(limitName) + ")" : std::string(" (physical memory)"));
}

}  // namespace

std::string latticeTooLarge(const Lattice& L, uint64_t memoryLimit, const char* limitName) {
  const uint64_t limit = hostMemoryLimit(memoryLimit), need = estimateLatticeBytes(L);
  if (limit == 0 || need <= limit) return {};
  uint64_t boxes = 1;
  for (int a = 0; a < 3; ++a) boxes *= uint64_t(std::max(1, L.counts[a] - L.degree[a]));
  const std::string dims = std::to_string(L.counts[0]) + "x" + std::to_string(L.counts[1]) + "x" + std::to_string(L.counts[2]);
  const std::string deg = std::to_string(L.degree[0]) + "," + std::to_string(L.degree[1]) + "," + std::to_string(L.degree[2]);
  return "the " + dims + " lattice (up to " + std::to_string(boxes) + " knot boxes of degree " + deg + ") needs about " +
         formatBytes(need) + " of host memory to evaluate, more than the limit of " + limitText(limit, memoryLimit, limitName) +
         "; use fewer control points";
}

JobEstimate estimateSmoothJob(const Mesh& mesh, double S, int level, size_t realBytes, bool deviceIsHost) {
  const double nv = double((level + 1) * (level + 2) / 2), tris = double(level) * level, nt = double(mesh.triangles.size());
  const double r4 = 4.0 * double(realBytes);   // one real4
  // Device, per sub-triangle: header, record, patch and tessellation (positions and normals); per
  // input triangle the pre-compute's inputs and PN record and about one clip triangle (layout.h: slot
  // normals, PN record, clip reals; 68 bytes of triangle, clip header and count words).
  const double device = S * (16 + SFFD_SUB_STRIDE * r4 + SFFD_PATCH_STRIDE * r4 + 2 * nv * r4) +
                        nt * ((SFFD_SLOT_NORMAL_STRIDE + SFFD_PN_STRIDE + SFFD_CLIP_REAL_STRIDE) * r4 + 68) +
                        double(meshBytes(mesh, false));
  // Host, per sub-triangle, at the peak (the weld, smooth's result()): its parent and corner
  // barycentrics (SubTrianglePreImages, 76 bytes), the pre-images and positions and normals of the
  // patch vertices (9 doubles), the weld's two hash entries and the welded vertex with push_back's
  // slack (about 256 bytes), the triangles; then the writer's position index (76 bytes a vertex, as
  // for classic).
  const double perSub = 4 + 9 * 8 + nv * 72 + nv * 256 + tris * 24 + nv * 76;
  // The input held by the Deformer, the session's copy and the prepared mesh, and per triangle the
  // topology and clip triangles (about 256 bytes).
  const double input = 3.0 * double(meshBytes(mesh, true)) + nt * 256;
  JobEstimate e;
  const double host = input + S * perSub + (deviceIsHost ? device : 0) + (1 << 20);
  e.hostBytes = host >= 1.8e19 ? UINT64_MAX : uint64_t(host);
  e.deviceBytes = device >= 1.8e19 ? UINT64_MAX : uint64_t(device);
  e.chunkVertices = uint64_t(S * nv);
  e.chunks = 1;
  return e;
}

void checkHostBytesFit(uint64_t bytes, uint64_t memoryLimit, const char* limitName, const std::string& subject,
                       const std::string& hint) {
  const uint64_t limit = hostMemoryLimit(memoryLimit);
  if (limit > 0 && bytes > limit)
    throw Error(ErrorKind::Input, subject + " about " + formatBytes(bytes) + " of host memory, more than the limit of " +
                                      limitText(limit, memoryLimit, limitName) + "; " + hint);
}

void checkHostFits(const JobEstimate& e, uint64_t memoryLimit, const char* limitName, const char* what) {
  checkHostBytesFit(e.hostBytes, memoryLimit, limitName, std::string("the ") + what + " needs",
                    "use a smaller mesh, a longer edge length or a lower tessellation level");
}

void checkJobFits(const JobEstimate& e, const PackedLattice& P, size_t realBytes, const DeviceLimits* limits,
                  uint64_t memoryLimit, const char* limitName) {
  checkHostBytesFit(e.hostBytes, memoryLimit, limitName, "the job needs", "use a smaller mesh or split it");
  if (limits) {
    uint64_t coeffBytes = P.coeffs.size() * uint64_t(realBytes);
    if (coeffBytes > limits->maxStorageBufferRange)
      throw Error(ErrorKind::Input, "the lattice's Bezier coefficients take " + formatBytes(coeffBytes) +
                                        ", more than one storage binding of this device can hold (" +
                                        formatBytes(limits->maxStorageBufferRange) + "); use fewer control points or float precision (DeformOptions::precision)");
  }
}

}  // namespace sffd
