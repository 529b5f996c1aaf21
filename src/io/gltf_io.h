// glTF 2.0 meshes (.gltf with its buffers, .glb): read with tinygltf, written here (one mesh, one
// primitive per material, float attributes, uint32 indices). docs/CLI.md "glTF".
#pragma once
#include <string>

#include "model/mesh.h"

namespace sffd::meshio {

// Every triangle primitive of the default scene (the first when none is named), node transforms
// applied: POSITION, NORMAL, TEXCOORD_0 (v flipped to the OBJ convention), COLOR_0 and the material.
// Strips and fans are triangulated; points and lines are skipped with a warning.
Mesh readGltf(const std::string& path, const std::string& bytes);

// .glb: one file; .gltf: the JSON and a buffer file named like it with .bin, both written whole or
// not at all. `mesh` is checked by writeMesh.
void writeGltf(const std::string& path, const Mesh& mesh);

// An animation: frames[0] is the mesh, every further frame (same vertices and triangles) a morph
// target of POSITION and NORMAL differences, shown one after the other at `fps` frames a second by
// an animation of the mesh's weights (linear: each frame blends into the next). .glb or .gltf.
void writeGltfAnimation(const std::string& path, const std::vector<Mesh>& frames, double fps);

}  // namespace sffd::meshio
