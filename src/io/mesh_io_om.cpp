// OpenMesh's own binary format (.om), read by OpenMesh. OpenMesh's .om reader is compiled with its
// asserts on and trusts the file (a damaged chunk header aborts the whole program, as fuzzing showed),
// so it runs in a forked child process: the child reads the file with OpenMesh, walks every face loop
// with range-checked handles and sends positions, normals and polygons back through a pipe; if it dies
// or fails, the file is reported as damaged. The header's counts are checked against the file size first.
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include <sffd/error.h>
#include "io/io_util.h"
#include "io/mesh_io_internal.h"

// Sanitizer runtimes (ASan, UBSan, libFuzzer's) let a program register a callback run when they report
// an error; a forked child must not run its parent's (libFuzzer's writes a crash file for the parent's
// input). Weak: null in an ordinary build.
extern "C" void __sanitizer_set_death_callback(void (*callback)(void)) __attribute__((weak));

namespace sffd::meshio {
namespace {

using OmMesh = OpenMesh::PolyMesh_ArrayKernelT<OpenMesh::DefaultTraitsDouble>;

template <typename T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// In the child: OpenMesh reads `text`; the result is serialised into `out`:
// u64 nv, u64 nf, u8 hasNormals, nv x 3 doubles positions, [nv x 3 doubles normals], then per face
// u32 n and n u32 vertex indices. Returns an exit status (0 ok).
int readInChild(const std::string& text, std::string& out) {
  ::omlog().disable();
  ::omout().disable();
  ::omerr().disable();
  OmMesh om;
  om.request_vertex_normals();
  OpenMesh::IO::Options opt = OpenMesh::IO::Options::VertexNormal;
  opt += OpenMesh::IO::Options::Binary;
  std::istringstream is(text, std::ios::in | std::ios::binary);
  if (!OpenMesh::IO::read_mesh(om, is, ".om", opt)) return 3;
  const bool hasNormals = opt.check(OpenMesh::IO::Options::VertexNormal) && om.has_vertex_normals();
  const size_t n = om.n_vertices();
  put(out, uint64_t(n));
  put(out, uint64_t(om.n_faces()));
  put(out, uint8_t(hasNormals));
  for (size_t v = 0; v < n; ++v) {
    const auto& p = om.point(OmMesh::VertexHandle{int(v)});
    for (int c = 0; c < 3; ++c) put(out, double(p[c]));
  }
  if (hasNormals)
    for (size_t v = 0; v < n; ++v) {
      const auto& q = om.normal(OmMesh::VertexHandle{int(v)});
      for (int c = 0; c < 3; ++c) put(out, double(q[c]));
    }
  const int nh = int(om.n_halfedges());
  std::vector<uint32_t> poly;
  for (size_t f = 0; f < om.n_faces(); ++f) {
    OmMesh::HalfedgeHandle h0 = om.halfedge_handle(OmMesh::FaceHandle{int(f)}), h = h0;
    if (h0.idx() < 0 || h0.idx() >= nh) return 4;
    poly.clear();
    do {
      OmMesh::VertexHandle vh = om.to_vertex_handle(h);
      if (vh.idx() < 0 || size_t(vh.idx()) >= n || int(poly.size()) > nh) return 4;
      poly.push_back(uint32_t(vh.idx()));
      h = om.next_halfedge_handle(h);
      if (h.idx() < 0 || h.idx() >= nh) return 4;
    } while (h != h0);
    put(out, uint32_t(poly.size()));
    for (uint32_t i : poly) put(out, i);
  }
  return 0;
}

bool writeAll(int fd, const std::string& s) {
  size_t done = 0;
  while (done < s.size()) {
    ssize_t w = ::write(fd, s.data() + done, s.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    done += size_t(w);
  }
  return true;
}

struct Reader {
  const std::string& s;
  size_t pos = 0;
  template <typename T>
  bool get(T& v) {
    if (s.size() - pos < sizeof v) return false;
    std::memcpy(&v, s.data() + pos, sizeof v);
    pos += sizeof v;
    return true;
  }
};

}  // namespace

Mesh readOm(const std::string& path, const std::string& text) {
  size_t dropped = 0;   // polygons without area (addPolygon)
  if (text.size() < 16 || text[0] != 'O' || text[1] != 'M') throw inputError(path, 0, "not an OpenMesh .om file");
  uint32_t nv = 0, nf = 0, ne = 0;
  std::memcpy(&nv, text.data() + 4, 4);
  std::memcpy(&nf, text.data() + 8, 4);
  std::memcpy(&ne, text.data() + 12, 4);
  // Positions alone take 12 bytes a vertex; a face or an edge at least one more byte.
  if (uint64_t(nv) * 12 + nf + ne > text.size())
    throw inputError(path, 0, "truncated: the header declares " + std::to_string(nv) + " vertices, " + std::to_string(nf) +
                                  " faces and " + std::to_string(ne) + " edges, more than " + std::to_string(text.size()) +
                                  " bytes can hold");
  if (nf == 0) throw inputError(path, 0, "no faces");

  int fds[2];
  if (::pipe(fds) != 0) throw Error(ErrorKind::Internal, path + ": cannot create a pipe: " + std::strerror(errno));
  std::fflush(nullptr);
  pid_t pid = ::fork();
  if (pid < 0) {
    int e = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw Error(ErrorKind::Internal, path + ": cannot fork: " + std::strerror(e));
  }
  if (pid == 0) {   // child: never returns
    ::close(fds[0]);
    int devnull = ::open("/dev/null", O_WRONLY);
    if (devnull >= 0) {
      ::dup2(devnull, 1);
      ::dup2(devnull, 2);
    }
    // The parent's handlers (a sanitizer's, a fuzzer's, a caller's SIGALRM) are not the child's: a
    // crash in OpenMesh just ends the child, and the alarm below really ends it.
    for (int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL, SIGALRM}) ::signal(sig, SIG_DFL);
    if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(nullptr);
    ::alarm(600);   // a file that sends OpenMesh into a loop
    int rc = 5;
    try {
      std::string out;
      rc = readInChild(text, out);
      if (rc == 0 && !writeAll(fds[1], out)) rc = 6;
    } catch (...) {
      rc = 7;
    }
    ::_exit(rc);
  }
  ::close(fds[1]);
  std::string data;
  char buf[1 << 16];
  while (true) {
    ssize_t r = ::read(fds[0], buf, sizeof buf);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    data.append(buf, size_t(r));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string why = WIFSIGNALED(status) ? "OpenMesh crashed on it" : "OpenMesh could not read it";
    throw inputError(path, 0, "damaged or unsupported .om file (" + why + ")");
  }

  Reader rd{data};
  uint64_t n = 0, faces = 0;
  uint8_t hasNormals = 0;
  auto damaged = [&]() { return inputError(path, 0, "damaged .om file"); };
  if (!rd.get(n) || !rd.get(faces) || !rd.get(hasNormals)) throw damaged();
  if (n != nv || faces != nf)
    throw inputError(path, 0, "damaged .om file: read " + std::to_string(n) + " vertices and " + std::to_string(faces) +
                                  " faces, the header declares " + std::to_string(nv) + " and " + std::to_string(nf));
  Mesh mesh;
  mesh.positions.resize(n);
  for (size_t v = 0; v < n; ++v) {
    for (int c = 0; c < 3; ++c)
      if (!rd.get(mesh.positions[v][c])) throw damaged();
    const glm::dvec3& p = mesh.positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw inputError(path, 0, "vertex " + std::to_string(v) + ": non-finite coordinate");
  }
  if (hasNormals) {
    mesh.normals.resize(n);
    for (size_t v = 0; v < n; ++v)
      for (int c = 0; c < 3; ++c)
        if (!rd.get(mesh.normals[v][c])) throw damaged();
  }
  std::vector<uint32_t> poly;
  for (uint64_t f = 0; f < faces; ++f) {
    uint32_t k = 0;
    if (!rd.get(k) || k < 3 || k > n) throw damaged();
    poly.resize(k);
    for (uint32_t& i : poly)
      if (!rd.get(i) || i >= n) throw damaged();
    addPolygon(mesh, poly.data(), poly.size(), dropped);
  }
  std::vector<uint8_t> fromFile(hasNormals ? n : 0, 1);
  noteDroppedPolygons(mesh, dropped);
  finishMesh(mesh, fromFile, path);
  return mesh;
}

}  // namespace sffd::meshio
