// Internal interface of the lattice readers (lattice_io*.cpp): each gets the file's bytes.
#pragma once
#include <string>

#include "io/lattice_io.h"

namespace sffd::latticeio {

// What readLattice does once the file is read: dispatch by the extension of `path` (used by the fuzz targets).
Lattice readLatticeBytes(const std::string& path, std::string text, const LatticeReadOptions& options = {});

// `memoryLimit`: as LatticeReadOptions::memoryLimit, checked before the control points are allocated.
Lattice readJson(const std::string& path, const std::string& text, uint64_t memoryLimit = 0);
Lattice readPrm(const std::string& path, const std::string& text);
// readPrm in two steps (the PyGeM parameters of <sffd/lattice.h>): the file's values, then their lattice.
PygemParameters parsePrm(const std::string& path, const std::string& text);
Lattice latticeOfPrm(const PygemParameters& parameters, const std::string& source);
Lattice readNpy(const std::string& path, const std::string& text, const LatticeReadOptions& options);

// The .npy (control points only, float64) and .prm (PyGeM; one Bezier box, a rotated box) forms.
void writeNpy(const std::string& path, const Lattice& lattice);
void writePrm(const std::string& path, const Lattice& lattice);
void writePrmParameters(const std::string& path, const PygemParameters& parameters);
// The control net as a legacy VTK structured grid (ParaView), with displacements from the identity.
void writeVtk(const std::string& path, const Lattice& lattice);

}  // namespace sffd::latticeio
