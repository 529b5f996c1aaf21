// What the public-API tests share: a device opened by name with validation on, and a mesh made from
// flat arrays (positions xyz..., triangles abc...) the way an application hands them over.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <sffd/sffd.h>

namespace sffd::testing {

inline Device openTestDevice(const std::string& name) {
  DeviceRequest r;
  r.name = name;
  r.validation = true;
  return Device::open(r);
}

inline Mesh meshFromArrays(const std::vector<double>& xyz, const std::vector<uint32_t>& tri) {
  MeshView view;
  view.positions = xyz.data();
  view.vertexCount = xyz.size() / 3;
  view.triangles = tri.data();
  view.triangleCount = tri.size() / 3;
  return meshFromView(view);
}

}  // namespace sffd::testing
