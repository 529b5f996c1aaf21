// What a lattice does to a given mesh that the user may not expect: vertices outside the lattice's
// box (extrapolated or left unmoved, by the lattice's outside rule), knots that make the volume
// discontinuous (an interior knot repeated more than the degree: the map jumps there), and a mesh too
// small for float within the lattice's knot spans. The CLI prints each as one warning line; a library
// user can call them the same way.
#pragma once
#include <string>

#include <sffd/lattice.h>
#include <sffd/mesh.h>

namespace sffd {

// Share of the mesh's vertices whose lattice parameter lies outside the lattice's domain, 0..1.
double shareOutsideLattice(const Mesh& mesh, const Lattice& lattice);

// One line (without "sffd: warning: ") when more than half of the vertices lie outside; else empty.
std::string outsideWarning(double shareOutside, const Lattice& lattice, const std::string& latticeName);

// One line naming the first interior knot whose multiplicity exceeds its axis' degree; else empty.
std::string discontinuityWarning(const Lattice& lattice, const std::string& latticeName);

// The kernels evaluate the lattice from a parameter's distance to the knots, to about 2^-24 of a knot
// span in float and 2^-53 in double: a mesh much smaller than the spans it lies in is resolved only to
// that (a mesh 1e-6 of a span across: to about 3 % of its size in float; the local frame cannot help, the
// spans are the lattice's). One line when that is 1/128 of the mesh's size or more; else empty.
std::string resolutionWarning(const Mesh& mesh, const Lattice& lattice, bool doublePrecision, const std::string& latticeName);

}  // namespace sffd
