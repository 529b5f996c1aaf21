// sffd.deform, sffd.Deformer and sffd.deform_points (<sffd/deformer.h>): the caller's arrays become a
// MeshView, the result Mesh becomes fresh arrays.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <sffd/sffd.h>

#include "arrays.h"

namespace py = pybind11;
using namespace py::literals;

namespace sffd::python {
namespace {

using DeviceFor = std::shared_ptr<Device> (*)(py::handle);
DeviceFor gDeviceFor = nullptr;

Method methodOf(const std::string& name) {
  if (name == "smooth") return Method::Smooth;
  if (name == "classic") return Method::Classic;
  if (name == "accurate") return Method::Accurate;
  throw Error(ErrorKind::Input, "method must be 'smooth', 'classic' or 'accurate', not '" + name + "'");
}

Precision precisionOf(const std::string& name) {
  if (name == "auto") return Precision::Auto;
  if (name == "float") return Precision::Float;
  if (name == "double") return Precision::Double;
  throw Error(ErrorKind::Input, "precision must be 'auto', 'float' or 'double', not '" + name + "'");
}

py::tuple meshArrays(const Mesh& m) { return py::make_tuple(toArray(m.positions), toArray(m.triangles), toArray(m.normals)); }

// A Deformer and the device it runs on, which must outlive it (members are destroyed in reverse order).
struct PyDeformer {
  std::shared_ptr<Device> device;
  std::unique_ptr<Deformer> deformer;
};

struct Inputs {
  std::vector<glm::dvec3> positions, normals;
  std::vector<uint32_t> triangles;
  MeshView view() const {
    MeshView v;
    v.positions = &positions[0].x, v.vertexCount = positions.size();
    if (!normals.empty()) v.normals = &normals[0].x;
    v.triangles = triangles.data(), v.triangleCount = triangles.size() / 3;
    return v;
  }
};

Inputs inputsOf(py::handle vertices, py::handle triangles, py::handle normals) {
  Inputs in;
  in.positions = points(vertices, "vertices");
  if (in.positions.empty()) throw Error(ErrorKind::Input, "vertices: no vertices");
  in.triangles = triangleIndices(triangles, in.positions.size());
  if (!normals.is_none()) {
    in.normals = points(normals, "normals");
    if (in.normals.size() != in.positions.size())
      throw Error(ErrorKind::Input, "normals: expected one per vertex (" + std::to_string(in.positions.size()) + "), got " +
                                        std::to_string(in.normals.size()));
  }
  return in;
}

// A real-number option: any Python or numpy number (numpy's float32 and integer scalars are no Python
// float or int), else an InputError naming it (pybind11's cast said only "Unable to cast Python instance").
double numberOf(py::handle a, const char* what, const char* expected) {
  if (py::isinstance<py::str>(a) || py::isinstance<py::bool_>(a) || !PyNumber_Check(a.ptr()))
    throw Error(ErrorKind::Input, std::string(what) + ": expected " + expected + ", got " + std::string(py::repr(a)));
  return py::float_(py::reinterpret_borrow<py::object>(a)).cast<double>();
}

// crease_angle: None or "auto" (the relative rule, kCreaseAngleAuto) or degrees 0..180, as --crease-angle.
double creaseAngleOf(py::handle a) {
  if (a.is_none() || (py::isinstance<py::str>(a) && a.cast<std::string>() == "auto")) return kCreaseAngleAuto;
  const double d = numberOf(a, "crease_angle", "None, 'auto' or degrees 0..180");
  if (!(d >= 0 && d <= 180)) throw Error(ErrorKind::Input, "crease_angle: expected degrees 0..180, got " + std::string(py::repr(a)));
  return d;
}

PyDeformer makeDeformer(py::handle vertices, py::handle triangles, const Lattice& lattice, const std::string& method,
                        py::handle backend, py::object edgeLength, int tess, py::handle normals, bool strict,
                        const std::string& precision, py::handle creaseAngle, bool once = false) {
  DeformOptions o;
  o.once = once;
  o.creaseAngleDeg = creaseAngleOf(creaseAngle);
  o.method = methodOf(method);
  o.edgeLength = edgeLength.is_none() ? 0.0 : numberOf(edgeLength, "edge_length", "None or a length > 0 in model units");
  o.tess = tess;
  o.strict = strict;
  o.precision = precisionOf(precision);
  Inputs in = inputsOf(vertices, triangles, normals);
  PyDeformer d;
  d.device = gDeviceFor(backend);
  d.deformer = std::make_unique<Deformer>(*d.device, in.view(), lattice, o);
  return d;
}

}  // namespace

void bindDeform(py::module_& m, DeviceFor deviceFor) {
  gDeviceFor = deviceFor;
  py::class_<PyDeformer>(m, "Deformer",
                         "A mesh prepared once on a device for lattices of one structure; deform(lattice) as often as asked.")
      .def(py::init(&makeDeformer), "vertices"_a, "triangles"_a, "lattice"_a, py::kw_only(), "method"_a = "smooth",
           "backend"_a = "auto", "edge_length"_a = py::none(), "tess"_a = 10, "normals"_a = py::none(), "strict"_a = false,
           "precision"_a = "auto", "crease_angle"_a = py::none(), "once"_a = false)
      .def(
          "write",
          [](PyDeformer& d, const std::string& path, py::object lattice, bool binary) {
            if (!lattice.is_none()) d.deformer->deform(lattice.cast<const Lattice&>());
            // The result streamed into the file as it is downloaded and welded: never held whole.
            MeshFileWriter out(path, {.significantDigits = d.deformer->resultDigits(), .binary = binary});
            d.deformer->streamResult(out);
            return py::make_tuple(out.vertexCount(), out.triangleCount());
          },
          "path"_a, "lattice"_a = py::none(), py::kw_only(), "binary"_a = false,
          "Deforms with `lattice` if one is given, then writes the result to `path` as write_mesh would, "
          "streamed: (vertex count, triangle count).")
      .def(
          "deform",
          [](PyDeformer& d, const Lattice& lattice) {
            d.deformer->deform(lattice);
            return meshArrays(d.deformer->result());
          },
          "lattice"_a, "(vertices, triangles, normals) for the lattice's current control points.")
      .def_property_readonly("device", [](const PyDeformer& d) { return d.device; })
      .def_property_readonly("sub_triangles", [](const PyDeformer& d) { return d.deformer->subTriangles(); })
      .def_property_readonly("timings", [](const PyDeformer& d) {
        const Timings& t = d.deformer->timings();
        py::dict steps;   // the last deform()'s dispatches by label, summed over chunks
        for (const auto& [label, ms] : t.steps) {
          const py::str key(label);
          steps[key] = (steps.contains(key) ? steps[key].cast<double>() : 0.0) + ms;
        }
        return py::dict("pn_ms"_a = t.pnMs, "clip_ms"_a = t.clipMs, "deform_ms"_a = t.deformMs, "wall_ms"_a = t.wallMs,
                        "weld_ms"_a = t.weldMs, "steps_ms"_a = steps);
      });

  m.def(
      "deform",
      [](py::handle vertices, py::handle triangles, const Lattice& lattice, const std::string& method, py::handle backend,
         py::object edgeLength, int tess, py::handle normals, bool strict, const std::string& precision,
         py::handle creaseAngle) {
        PyDeformer d =
            makeDeformer(vertices, triangles, lattice, method, backend, edgeLength, tess, normals, strict, precision, creaseAngle);
        d.deformer->deform(lattice);
        return meshArrays(d.deformer->result());
      },
      "vertices"_a, "triangles"_a, "lattice"_a, "method"_a = "smooth", "backend"_a = "auto", "edge_length"_a = py::none(),
      "tess"_a = 10, "normals"_a = py::none(), "strict"_a = false, "precision"_a = "auto", "crease_angle"_a = py::none(),
      "Deforms a triangle mesh: (vertices, triangles, normals) as float64, uint32, float64 arrays.");

  m.def(
      "read_mesh", [](const std::string& path) { return meshArrays(readMesh(path)); }, "path"_a,
      "Reads .obj .off .ply .stl .om (.bpt): (vertices, triangles, normals); normals computed where the file has none.");
  m.def(
      "write_mesh",
      [](const std::string& path, py::handle vertices, py::handle triangles, py::handle normals, bool binary) {
        Inputs in = inputsOf(vertices, triangles, normals);
        writeMesh(path, meshFromView(in.view()), {.binary = binary});
      },
      "path"_a, "vertices"_a, "triangles"_a, "normals"_a = py::none(), py::kw_only(), "binary"_a = false,
      "Writes by extension (.obj .ply .off .stl .gltf .glb); binary: binary .ply and .stl.");

  // Classic FFD of bare points (sffd.FFD.__call__). A Mesh needs a triangle: one degenerate triangle
  // over point 0 is handed over, and fixed normals, so that none is computed; the kernel moves each
  // point on its own.
  m.def(
      "deform_points",
      [](py::handle pts, const Lattice& lattice, py::handle backend, const std::string& precision) {
        Inputs in;
        in.positions = points(pts, "points");
        if (in.positions.empty()) return toArray(in.positions);
        in.normals.assign(in.positions.size(), glm::dvec3(0, 0, 1));
        in.triangles = {0, 0, 0};
        std::shared_ptr<Device> device = gDeviceFor(backend);
        DeformOptions o;
        o.method = Method::Classic;
        o.precision = precisionOf(precision);
        Deformer d(*device, in.view(), lattice, o);
        d.deform(lattice);
        return toArray(d.result().positions);
      },
      "points"_a, "lattice"_a, "backend"_a = "auto", "precision"_a = "auto",
      "Classic FFD of an (n, 3) array of points: an (n, 3) float64 array, the same order.");
}

}  // namespace sffd::python
