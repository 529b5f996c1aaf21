// Mesh helpers inside the library; the Mesh type and its files are public (<sffd/mesh.h>).
#pragma once
#include <sffd/mesh.h>

namespace sffd {

// Angle-weighted vertex normals from the triangles (vertices with no area keep +z).
void computeVertexNormals(Mesh& mesh);

// Assigns weldId from exact position equality.
void weldPositions(Mesh& mesh);

}  // namespace sffd
