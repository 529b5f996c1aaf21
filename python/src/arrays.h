// numpy arrays in and out of the binding: (n, 3) rows of reals or of triangle indices.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cstring>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <sffd/error.h>

namespace sffd::python {

namespace py = pybind11;
static_assert(sizeof(glm::dvec3) == 3 * sizeof(double), "glm::dvec3 must be three packed doubles");
using RealRows = py::array_t<double, py::array::c_style | py::array::forcecast>;

inline std::string shapeOf(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// Any (n, cols) array of real or integer numbers as C-contiguous float64 (copied only when it is not
// already that); an input Error naming `what` otherwise.
inline RealRows realRows(py::handle obj, const char* what, py::ssize_t cols = 3) {
  py::array a = py::array::ensure(obj);
  if (!a) throw Error(ErrorKind::Input, std::string(what) + ": expected a numpy array (or a nested list) of numbers");
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw Error(ErrorKind::Input, std::string(what) + ": expected real numbers, got dtype " + std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != cols)
    throw Error(ErrorKind::Input, std::string(what) + ": expected shape (n, " + std::to_string(cols) + "), got " + shapeOf(a));
  return RealRows::ensure(a);
}

inline std::vector<glm::dvec3> points(py::handle obj, const char* what) {
  RealRows a = realRows(obj, what);
  std::vector<glm::dvec3> p(size_t(a.shape(0)));
  if (!p.empty()) std::memcpy(p.data(), a.data(), p.size() * sizeof(glm::dvec3));   // dvec3: three packed doubles
  return p;
}

// (m, 3) integer vertex indices, each in 0..vertexCount-1, as uint32.
inline std::vector<uint32_t> triangleIndices(py::handle obj, size_t vertexCount) {
  py::array a = py::array::ensure(obj);
  if (!a || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
    throw Error(ErrorKind::Input, "triangles: expected an integer array of vertex indices");
  if (a.ndim() != 2 || a.shape(1) != 3) throw Error(ErrorKind::Input, "triangles: expected shape (m, 3), got " + shapeOf(a));
  auto t = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  std::vector<uint32_t> out(size_t(t.size()));
  const int64_t* d = t.data();
  for (size_t i = 0; i < out.size(); ++i) {
    if (d[i] < 0 || uint64_t(d[i]) >= vertexCount)
      throw Error(ErrorKind::Input, "triangles: vertex index " + std::to_string(d[i]) + " out of range 0.." +
                                        std::to_string(int64_t(vertexCount) - 1));
    out[i] = uint32_t(d[i]);
  }
  return out;
}

inline py::array_t<double> toArray(const std::vector<glm::dvec3>& v) {
  py::array_t<double> a({py::ssize_t(v.size()), py::ssize_t(3)});
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(glm::dvec3));
  return a;
}

inline py::array_t<uint32_t> toArray(const std::vector<std::array<uint32_t, 3>>& t) {
  py::array_t<uint32_t> a({py::ssize_t(t.size()), py::ssize_t(3)});
  if (!t.empty()) std::memcpy(a.mutable_data(), t.data(), t.size() * sizeof(t[0]));
  return a;
}

// Three integers, or one for every axis (the command line's rule for U,V,W options).
inline std::array<int, 3> triple(py::handle obj, const char* what) {
  if (py::isinstance<py::int_>(obj)) {
    const int v = obj.cast<int>();
    return {v, v, v};
  }
  try {
    auto v = obj.cast<std::vector<int>>();
    if (v.size() == 3) return {v[0], v[1], v[2]};
  } catch (const py::cast_error&) {
  }
  throw Error(ErrorKind::Input, std::string(what) + ": expected an integer or three");
}

}  // namespace sffd::python
