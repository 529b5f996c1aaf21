// sffd.Lattice and the PyGeM parameters behind sffd.FFD (<sffd/lattice.h>).
//
// control_points is a numpy view on the lattice's own storage, kept alive by the view: edits in place
// (L.control_points[3] += 0.1) and assignment (L.control_points = P) both reach the C++ lattice. No
// Python method resizes that storage (preset() and copy() make new lattices), so a view never dangles.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <sffd/sffd.h>

#include "arrays.h"

namespace py = pybind11;
using namespace py::literals;

namespace sffd::python {
namespace {

py::array controlPointView(py::object self) {
  Lattice& L = self.cast<Lattice&>();
  return py::array_t<double>({py::ssize_t(L.controlPoints.size()), py::ssize_t(3)},
                             {py::ssize_t(sizeof(glm::dvec3)), py::ssize_t(sizeof(double))},
                             reinterpret_cast<double*>(L.controlPoints.data()), self);
}

void setControlPoints(Lattice& L, py::handle value) {
  std::vector<glm::dvec3> p = points(value, "control_points");
  if (p.size() != L.controlPoints.size())
    throw Error(ErrorKind::Input, "control_points: expected " + std::to_string(L.controlPoints.size()) + " points, got " +
                                      std::to_string(p.size()));
  std::copy(p.begin(), p.end(), L.controlPoints.begin());   // in place: views stay valid
}

// A copy of read-only structure that refuses writes (numpy's writeable flag off): writes to a plain copy
// were silently lost.
py::array readOnly(py::array a) {
  a.attr("flags").attr("writeable") = false;
  return a;
}

py::array_t<double> mat3(const glm::dmat3& m) {   // row-major, as numpy reads it: out[r][c] = m[c][r]
  py::array_t<double> a({3, 3});
  auto w = a.mutable_unchecked<2>();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) w(r, c) = m[c][r];
  return a;
}

glm::dvec3 vec3(py::handle obj, const char* what) {
  auto v = obj.cast<std::vector<double>>();
  if (v.size() != 3) throw Error(ErrorKind::Input, std::string(what) + ": expected three numbers");
  return {v[0], v[1], v[2]};
}

PygemParameters pygemParameters(py::handle counts, py::handle length, py::handle origin, py::handle angleDeg, py::handle mu) {
  PygemParameters P;
  P.counts = triple(counts, "n_control_points");
  P.length = vec3(length, "box_length");
  P.origin = vec3(origin, "box_origin");
  P.angleDeg = vec3(angleDeg, "rot_angle");
  P.mu = points(mu, "mu");
  return P;
}

}  // namespace

void bindLattice(py::module_& m) {
  py::class_<Lattice>(m, "Lattice", "A trivariate B-spline FFD lattice (<sffd/lattice.h>).")
      .def_static(
          "from_file",
          [](const std::string& path, py::object box, py::handle degree) {
            LatticeReadOptions o;
            o.npyDegree = triple(degree, "degree");
            if (!box.is_none()) {
              std::vector<glm::dvec3> b = points(box, "box");
              if (b.size() != 2) throw Error(ErrorKind::Input, "box: expected two points, (lo, hi)");
              o.haveMeshBox = true, o.meshBoxLo = b[0], o.meshBoxHi = b[1];
            }
            return readLattice(path, o);
          },
          "path"_a, "box"_a = py::none(), "degree"_a = std::array<int, 3>{2, 2, 2},
          "Reads .json, .prm (PyGeM) or .npy (control points only: give box=(lo, hi) and degree).")
      .def_static(
          "fitted",
          [](py::handle pts, py::handle counts, py::handle degree, double margin) {
            Mesh mesh;
            mesh.positions = points(pts, "points");
            return fitLattice(mesh, triple(counts, "counts"), triple(degree, "degree"), margin);
          },
          "points"_a, "counts"_a = std::array<int, 3>{5, 5, 5}, "degree"_a = std::array<int, 3>{2, 2, 2}, "margin"_a = 0.005,
          "An identity lattice around the points' bounding box, grown by margin times its largest extent.")
      .def_static(
          "box",
          [](py::handle lo, py::handle hi, py::handle counts, py::handle degree) {
            Lattice L = makeIdentityLattice(vec3(lo, "lo"), vec3(hi, "hi"), triple(counts, "counts"), triple(degree, "degree"));
            validateLattice(L, "Lattice.box");
            return L;
          },
          "lo"_a, "hi"_a, "counts"_a = std::array<int, 3>{5, 5, 5}, "degree"_a = std::array<int, 3>{2, 2, 2},
          "An identity lattice over the box [lo, hi].")
      .def(
          "preset",
          [](const Lattice& L, const std::string& name, double amount) {
            Lattice out = L;
            applyLatticePreset(out, name, amount);
            return out;
          },
          "name"_a, "amount"_a, "A new lattice: this one with a preset (twist, bend, taper, bulge, noise) applied.")
      .def(
          "refined", [](const Lattice& L, py::handle parts) { return refineLattice(L, triple(parts, "parts"), "Lattice.refined"); },
          "parts"_a, "A new lattice: every knot span of each axis split into parts (int or 3 ints) equal spans; the same volume.")
      .def(
          "elevated", [](const Lattice& L, py::handle by) { return elevateLattice(L, triple(by, "by"), "Lattice.elevated"); },
          "by"_a, "A new lattice: the degrees raised by `by` (int or 3 ints; at most 5); the same volume.")
      .def("copy", [](const Lattice& L) { return L; })
      .def("__copy__", [](const Lattice& L) { return L; })
      .def("__deepcopy__", [](const Lattice& L, py::dict) { return L; }, "memo"_a)
      .def("save", [](const Lattice& L, const std::string& path) { writeLattice(path, L); }, "path"_a,
           "Writes the format the extension names: .json (everything), .npy (control points), .prm (PyGeM's box), .vtk (control net).")
      .def("same_structure", [](const Lattice& a, const Lattice& b) { return sameLatticeStructure(a, b); }, "other"_a)
      .def_property("control_points", &controlPointView, &setControlPoints,
                    "(n, 3) float64 view on the control points, index (i*ny + j)*nz + k; edit in place or assign.")
      .def_property_readonly("counts", [](const Lattice& L) { return py::make_tuple(L.counts[0], L.counts[1], L.counts[2]); })
      .def_property_readonly("degree", [](const Lattice& L) { return py::make_tuple(L.degree[0], L.degree[1], L.degree[2]); })
      .def_property_readonly("knots", [](const Lattice& L) {
        py::list k;
        for (const auto& v : L.knots) k.append(readOnly(py::array_t<double>(py::ssize_t(v.size()), v.data())));
        return py::tuple(k);
      })
      .def_property_readonly("frame_linear", [](const Lattice& L) { return readOnly(mat3(L.frameLinear)); },
                             "M of the world -> parameter map p = M x + o")
      .def_property_readonly("frame_offset", [](const Lattice& L) {
        return readOnly(py::array_t<double>(3, &L.frameOffset.x));
      })
      .def_property_readonly("outside", [](const Lattice& L) { return L.outside == OutsideMode::Keep ? "keep" : "extrapolate"; })
      .def("__repr__", [](const Lattice& L) {
        auto t = [](const std::array<int, 3>& a) { return std::to_string(a[0]) + "x" + std::to_string(a[1]) + "x" + std::to_string(a[2]); };
        return "<sffd.Lattice " + t(L.counts) + " points, degree " + t(L.degree) + ">";
      });

  // PyGeM parameters as plain values: sffd.FFD (python/sffd/ffd.py) holds them the way PyGeM does.
  m.def("_read_pygem", [](const std::string& path) {
    PygemParameters P = readPygemParameters(path);
    auto v = [](const glm::dvec3& x) { return py::array_t<double>(3, &x.x); };
    return py::make_tuple(py::make_tuple(P.counts[0], P.counts[1], P.counts[2]), v(P.length), v(P.origin), v(P.angleDeg), toArray(P.mu));
  });
  m.def("_write_pygem", [](const std::string& path, py::handle counts, py::handle length, py::handle origin, py::handle angle,
                           py::handle mu) { writePygemParameters(path, pygemParameters(counts, length, origin, angle, mu)); });
  m.def("_pygem_lattice", [](py::handle counts, py::handle length, py::handle origin, py::handle angle, py::handle mu) {
    return pygemLattice(pygemParameters(counts, length, origin, angle, mu));
  });
}

}  // namespace sffd::python
