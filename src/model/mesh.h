// Mesh helpers inside the library; the Mesh type and its files are public (<sffd/mesh.h>).
#pragma once
#include <string>

#include <sffd/mesh.h>

namespace sffd {

// Angle-weighted vertex normals from the triangles (vertices with no area keep +z).
void computeVertexNormals(Mesh& mesh);

// Assigns weldId from exact position equality.
void weldPositions(Mesh& mesh);

// What every Mesh the library takes must hold, whatever it is taken for (writeMesh, MeshFileWriter's
// tables): each per-vertex field (normals, texcoords, colors, vertexPatch, vertexUV) empty or one per
// vertex, each per-triangle one (triangleMaterial, triangleGroup) empty or one per triangle, every index in
// range (triangles' corners; triangleMaterial, triangleGroup and vertexPatch into their tables). Throws an
// input Error "source: what" naming the field and its first bad element.
void checkMeshStructure(const Mesh& mesh, const std::string& source);

// What a mesh to deform must hold besides (the readers, meshFromView and the Deformer check it): weldId
// empty or one per vertex, each below the vertex count, the vertices of one id at one position; finite
// positions, texture coordinates, colours and, with `normals`, normals.
void validateMesh(const Mesh& mesh, const std::string& source, bool normals = true);

}  // namespace sffd
