// Sub-triangles of a parent triangle as the clipping steps produce them (METHOD.md 3.3, 4):
// where each corner lies on the parent, described so that points on a shared parent edge can be
// computed identically, bit for bit, from both triangles that share the edge.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace sffd {

enum class SubVertexKind : uint8_t {
  Corner0, Corner1, Corner2,   // exactly a parent corner
  Edge0, Edge1, Edge2,         // on parent edge e (corners e and (e+1)%3), see `t`
  Interior,
};

struct SubVertex {
  SubVertexKind kind = SubVertexKind::Interior;
  // Edge vertices: the parameter along the edge measured from its endpoint with the lower weldId
  // (the same number from both triangles sharing the edge). Unused otherwise.
  double t = 0;
  glm::dvec3 lam{0.0};   // parent barycentrics (consistent with kind and t)
};

struct SubTriangle {
  uint32_t parent = 0;
  std::array<SubVertex, 3> corners;   // counter-clockwise as the parent
};

}  // namespace sffd
