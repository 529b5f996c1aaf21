// Lattice files: the native JSON format, PyGeM .prm and reference-implementation .npy
// (docs/CLI.md "Inputs"), and the presets of `sffd lattice`.
#pragma once
#include <string>

#include "lattice.h"
#include "mesh.h"

namespace sffd {

struct LatticeReadOptions {
  std::array<int, 3> npyDegree{2, 2, 2};   // .npy files carry no degree
  // .npy files carry no box: the box is the bounding box of the mesh normalised by the caller
  // (--normalize, 0.99 by default). Required for .npy.
  bool haveMeshBox = false;
  glm::dvec3 meshBoxLo{0.0}, meshBoxHi{0.0};
};

// Reads by extension (.json .prm .npy). Throws an input Error ("file:line: what") on a bad file.
Lattice readLattice(const std::string& path, const LatticeReadOptions& options = {});

// Writes the native JSON format (shortest digits that read back to the same doubles) to a temporary file renamed into place.
void writeLatticeJson(const std::string& path, const Lattice& lattice);

// Applies a preset deformation (twist, bend, taper, bulge, noise) of the given amount to the
// control points, relative to the lattice box. Throws an input Error for an unknown name.
void applyLatticePreset(Lattice& lattice, const std::string& name, double amount);

}  // namespace sffd
