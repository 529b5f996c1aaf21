// OpenMesh's own binary format (.om), read by OpenMesh. Its header counts are checked against the file
// size first (OpenMesh reserves arrays from them), and the mesh it builds is checked before use: face
// loops are walked by hand with every handle range-checked, since OpenMesh's headers keep their asserts
// and a damaged file must not abort the program.
#include <cmath>
#include <cstring>
#include <sstream>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include "error.h"
#include "io_util.h"
#include "mesh_io_internal.h"

namespace sffd::meshio {
namespace {
using OmMesh = OpenMesh::PolyMesh_ArrayKernelT<OpenMesh::DefaultTraitsDouble>;
}

Mesh readOm(const std::string& path, const std::string& text) {
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

  ::omlog().disable();
  ::omout().disable();
  ::omerr().disable();
  OmMesh om;
  om.request_vertex_normals();
  OpenMesh::IO::Options opt = OpenMesh::IO::Options::VertexNormal;
  opt += OpenMesh::IO::Options::Binary;
  std::istringstream is(text, std::ios::in | std::ios::binary);
  bool ok = false;
  try {
    ok = OpenMesh::IO::read_mesh(om, is, ".om", opt);
  } catch (const std::exception& e) {
    throw inputError(path, 0, std::string("OpenMesh could not read the file: ") + e.what());
  }
  if (!ok) throw inputError(path, 0, "OpenMesh could not read the file (damaged or unsupported .om)");
  if (om.n_vertices() != nv || om.n_faces() != nf)
    throw inputError(path, 0, "damaged .om file: read " + std::to_string(om.n_vertices()) + " vertices and " +
                                  std::to_string(om.n_faces()) + " faces, the header declares " + std::to_string(nv) + " and " +
                                  std::to_string(nf));
  const bool hasNormals = opt.check(OpenMesh::IO::Options::VertexNormal) && om.has_vertex_normals();

  Mesh mesh;
  const size_t n = om.n_vertices();
  mesh.positions.resize(n);
  if (hasNormals) mesh.normals.resize(n);
  for (size_t v = 0; v < n; ++v) {
    OmMesh::VertexHandle vh{int(v)};
    const auto& p = om.point(vh);
    mesh.positions[v] = {p[0], p[1], p[2]};
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw inputError(path, 0, "vertex " + std::to_string(v) + ": non-finite coordinate");
    if (hasNormals) {
      const auto& q = om.normal(vh);
      mesh.normals[v] = {q[0], q[1], q[2]};
    }
  }
  const int nh = int(om.n_halfedges());
  std::vector<uint32_t> poly;
  for (size_t f = 0; f < om.n_faces(); ++f) {
    OmMesh::FaceHandle fh{int(f)};
    auto bad = [&]() { return inputError(path, 0, "damaged .om file: face " + std::to_string(f) + " has broken connectivity"); };
    OmMesh::HalfedgeHandle h0 = om.halfedge_handle(fh), h = h0;
    if (h0.idx() < 0 || h0.idx() >= nh) throw bad();
    poly.clear();
    do {
      OmMesh::VertexHandle vh = om.to_vertex_handle(h);
      if (vh.idx() < 0 || size_t(vh.idx()) >= n || int(poly.size()) > nh) throw bad();
      poly.push_back(uint32_t(vh.idx()));
      h = om.next_halfedge_handle(h);
      if (h.idx() < 0 || h.idx() >= nh) throw bad();
    } while (h != h0);
    if (poly.size() < 3) throw bad();
    fanTriangulate(poly.data(), poly.size(), mesh.triangles);
  }
  std::vector<uint8_t> fromFile(hasNormals ? n : 0, 1);
  finishMesh(mesh, fromFile, path);
  return mesh;
}

}  // namespace sffd::meshio
