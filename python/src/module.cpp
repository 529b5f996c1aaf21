// sffd._sffd: the pybind11 binding over the public C++ API (include/sffd). python/sffd/__init__.py
// re-exports it beside the pure-Python FFD class; docs/PYTHON.md is the manual.
//
// Arrays: any real dtype and any strides in (converted to C-contiguous float64 where needed), float64
// (positions, normals) and uint32 (triangles) out, always fresh copies. The GIL stays held: a Device is
// used from one thread at a time (any thread: sffd lets a GL context go at the end of each call).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include <sffd/sffd.h>

#include "arrays.h"

namespace py = pybind11;
using namespace py::literals;

namespace sffd::python {
namespace {

// sffd.Error and one subclass per ErrorKind; InputError is also a ValueError, DeviceError and
// InternalError RuntimeErrors, so that callers who know nothing of sffd catch what they expect.
PyObject *gError, *gInputError, *gDeviceError, *gInternalError, *gCancelled;

PyObject* newException(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  PyObject* type = PyErr_NewExceptionWithDoc((std::string("sffd.") + name).c_str(), doc, bases.ptr(), nullptr);
  if (!type) throw py::error_already_set();
  m.attr(name) = py::reinterpret_borrow<py::object>(type);   // the module's reference; ours lives for the process
  return type;
}

// The library names its options as C++ does (DeformOptions::precision); a Python caller sets keywords.
std::string inPythonWords(std::string what) {
  static const std::pair<const char*, const char*> words[] = {
      {"Precision::Float (or Auto) as DeformOptions::precision on an OpenGL ES device", "precision='float' (or 'auto') with backend='gles'"},
      {"float precision (DeformOptions::precision)", "precision='float'"},
      {"a longer edge length or a lower tessellation level", "a longer edge_length or a lower tess"},
      {"(DeformOptions::once)", "(once=True)"},
  };
  for (const auto& [library, python] : words)
    for (size_t at; (at = what.find(library)) != std::string::npos;) what.replace(at, std::strlen(library), python);
  return what;
}

void registerErrors(py::module_& m) {
  gError = newException(m, "Error", py::make_tuple(py::handle(PyExc_Exception)), "Every error sffd raises; str() is one line.");
  gInputError = newException(m, "InputError", py::make_tuple(py::handle(gError), py::handle(PyExc_ValueError)),
                             "Bad input data or options (ErrorKind::Input).");
  gDeviceError = newException(m, "DeviceError", py::make_tuple(py::handle(gError), py::handle(PyExc_RuntimeError)),
                              "No usable device, or the device refused the work (ErrorKind::Device).");
  gInternalError = newException(m, "InternalError", py::make_tuple(py::handle(gError), py::handle(PyExc_RuntimeError)),
                                "Anything else (ErrorKind::Internal).");
  gCancelled = newException(m, "Cancelled", py::make_tuple(py::handle(gError)), "A progress callback asked to stop.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      PyObject* type = e.kind() == ErrorKind::Input    ? gInputError
                       : e.kind() == ErrorKind::Device ? gDeviceError
                       : e.kind() == ErrorKind::Cancelled ? gCancelled
                                                          : gInternalError;
      PyErr_SetString(type, inPythonWords(e.what()).c_str());
    }
  });
}

// ---- devices: opened once per name and shared; the cache is emptied at interpreter exit, before
// the drivers' own teardown.
std::map<std::string, std::shared_ptr<Device>>& deviceCache() {
  static auto* cache = new std::map<std::string, std::shared_ptr<Device>>();   // never destroyed: see atexit below
  return *cache;
}

std::shared_ptr<Device> deviceFor(py::handle backend) {
  if (py::isinstance<Device>(backend)) return backend.cast<std::shared_ptr<Device>>();
  if (!py::isinstance<py::str>(backend)) throw Error(ErrorKind::Input, "backend must be a device name or an sffd.Device");
  std::string name = backend.cast<std::string>();
  auto& cache = deviceCache();
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  DeviceRequest request;
  request.name = name;
  auto device = std::make_shared<Device>(Device::open(request));
  cache[name] = device;
  return device;
}

void bindDevices(py::module_& m) {
  py::class_<DeviceEntry>(m, "DeviceEntry", "A device that can be opened here (sffd.devices()).")
      .def_property_readonly("label", [](const DeviceEntry& e) { return e.label; }, "the backend name that opens it")
      .def_property_readonly("name", [](const DeviceEntry& e) { return e.info.name; })
      .def_property_readonly("api", [](const DeviceEntry& e) { return e.info.api; })
      .def_property_readonly("type", [](const DeviceEntry& e) { return e.info.type; })
      .def_property_readonly("provider", [](const DeviceEntry& e) { return e.info.provider; })
      .def_property_readonly("driver", [](const DeviceEntry& e) { return e.info.driver; })
      .def("__repr__", [](const DeviceEntry& e) { return "<sffd.DeviceEntry " + e.label + ": " + e.info.name + " (" + e.info.type + ")>"; });
  m.def("devices", [] { return listDevices(); }, "Every device that can be opened here.");

  py::class_<Device, std::shared_ptr<Device>>(m, "Device", "An opened device; what backend= accepts besides a name.")
      .def(py::init([](const std::string& name, const std::string& match, const std::string& shaderCache) {
             return std::make_shared<Device>(
                 Device::open({.name = name, .deviceSubstring = match, .shaderCache = shaderCache}));
           }),
           "name"_a = "auto", "match"_a = "", "shader_cache"_a = "")
      .def_property_readonly("label", &Device::label)
      .def_property_readonly("name", [](const Device& d) { return d.info().name; })
      .def_property_readonly("api", [](const Device& d) { return d.info().api; })
      .def_property_readonly("type", [](const Device& d) { return d.info().type; })
      .def_property_readonly("float64", [](const Device& d) { return d.info().limits.float64; })
      .def("__repr__", [](const Device& d) { return "<sffd.Device " + d.label() + ": " + d.info().name + ">"; });
  m.def("device", [](py::handle backend) { return deviceFor(backend); }, "backend"_a = "auto",
        "The shared device a backend name opens (what deform() and Deformer use).");
  py::module_::import("atexit").attr("register")(py::cpp_function([] { deviceCache().clear(); }));
}

}  // namespace

void bindLattice(py::module_& m);
void bindDeform(py::module_& m, std::shared_ptr<Device> (*deviceFor)(py::handle));

}  // namespace sffd::python

PYBIND11_MODULE(_sffd, m) {
  m.doc() = "sffd: smooth free-form deformation of triangle meshes on any GPU (docs/PYTHON.md)";
  m.attr("__version__") = sffd::version();
  sffd::python::registerErrors(m);
  sffd::python::bindDevices(m);
  sffd::python::bindLattice(m);
  sffd::python::bindDeform(m, &sffd::python::deviceFor);
}
