// sffd/lattice.h: the FFD lattice, a trivariate B-spline volume of any degree 1..5 per axis
// (docs/METHOD.md 1), and lattice files.
//
// Plain data: control points in world space, knot vectors in lattice-parameter space, and an affine
// frame mapping world points to parameters (the identity for native lattices, PyGeM's rotated box
// for .prm lattices). Edit `controlPoints` and hand the lattice to Deformer::deform().
#pragma once
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <sffd/mesh.h>

namespace sffd {

// The most control points a lattice may have (24 bytes each: 384 MiB), and along one axis: what
// validateLattice, the lattice readers and every function that makes a lattice hold to.
inline constexpr size_t kMaxLatticeControlPoints = size_t(1) << 24;
inline constexpr int kMaxLatticeAxisCount = 4096;

enum class OutsideMode {
  Extrapolate,   // points outside the box follow the nearest knot box's polynomial (continuous)
  Keep,          // points outside the box are left unmoved (PyGeM)
};

struct Lattice {
  std::array<int, 3> degree{2, 2, 2};
  std::array<int, 3> counts{5, 5, 5};
  // Full knot vectors, counts[a] + degree[a] + 1 non-decreasing values each, in parameter space.
  std::array<std::vector<double>, 3> knots;
  // counts[0]*counts[1]*counts[2] points, index (i*counts[1] + j)*counts[2] + k, world coordinates.
  std::vector<glm::dvec3> controlPoints;
  // World -> parameter frame: p = frameLinear * x + frameOffset.
  glm::dmat3 frameLinear{1.0};
  glm::dvec3 frameOffset{0.0};
  OutsideMode outside = OutsideMode::Extrapolate;

  // Every int made a size_t first: an application building with -Wsign-conversion -Werror includes this.
  size_t pointCount() const { return size_t(counts[0]) * size_t(counts[1]) * size_t(counts[2]); }
  size_t index(int i, int j, int k) const { return (size_t(i) * size_t(counts[1]) + size_t(j)) * size_t(counts[2]) + size_t(k); }
  // Parameter-space domain of axis a: [knots[degree], knots[counts]].
  double domainLo(int a) const { return knots[size_t(a)][size_t(degree[size_t(a)])]; }
  double domainHi(int a) const { return knots[size_t(a)][size_t(counts[size_t(a)])]; }
};

// Every function here that takes a Lattice but sameLatticeStructure throws an input Error for one
// validateLattice refuses (a default-constructed Lattice has no knots), naming the function, its `source`
// or the file; setIdentityControlPoints needs all but the control points, which it sets.

// Clamped uniform knot vector over [lo, hi]: (degree+1) copies of each end, uniform interior knots. An input
// Error for a degree outside 1..5 or a count outside degree+1..kMaxLatticeAxisCount.
std::vector<double> clampedUniformKnots(int count, int degree, double lo, double hi);

// Checks degrees (1..5), counts > degree, the counts' limits (kMaxLatticeAxisCount, kMaxLatticeControlPoints),
// knot vector sizes and monotonicity, a non-empty domain, finite control points and an invertible frame
// with a finite offset.
// Throws an input Error naming `source`.
void validateLattice(const Lattice& lattice, const std::string& source);

// Same degrees, counts, knots, frame and outside rule (only the control points may differ): what a
// deformation prepared for one lattice may reuse for the other.
bool sameLatticeStructure(const Lattice& a, const Lattice& b);

// Sets every control point to the world position of its Greville parameter: the identity map.
void setIdentityControlPoints(Lattice& lattice);

// An axis-aligned lattice over [lo, hi] with clamped uniform knots and identity control points. Counts past
// the limits above are refused (an input Error) before anything is allocated.
Lattice makeIdentityLattice(glm::dvec3 lo, glm::dvec3 hi, std::array<int, 3> counts, std::array<int, 3> degree);

// An identity lattice around a mesh: its bounding box grown by `margin` times its largest extent
// on every side (what `sffd lattice` makes; a margin keeps every vertex strictly inside and gives a
// flat mesh a non-empty box).
Lattice fitLattice(const Mesh& mesh, std::array<int, 3> counts = {5, 5, 5}, std::array<int, 3> degree = {2, 2, 2},
                   double margin = 0.005);

// Applies a preset deformation (twist, bend, taper, bulge, noise) of the given amount to the
// control points, relative to the lattice box. Throws an input Error for an unknown name.
void applyLatticePreset(Lattice& lattice, const std::string& name, double amount);

// Knot insertion (Boehm): every knot span of axis a split into parts[a] equal spans (1: unchanged,
// up to 64). The volume is the same to rounding (about 1e-15 of the control net's size), with more
// control points to move. Throws an input Error naming `source` for a bad lattice or part count, or
// before anything is allocated when the work would need more than `memoryLimit` bytes of host memory
// (0: the physical memory; about 56 bytes a new control point), as elevateLattice does.
Lattice refineLattice(const Lattice& lattice, std::array<int, 3> parts, const std::string& source = "refine",
                      uint64_t memoryLimit = 0);

// Degree elevation: degree[a] raised by by[a] (the result stays <= 5), every interior knot's
// multiplicity raised as much, so the continuity and the volume are unchanged (to rounding); the knot
// vectors come back clamped over the same domain. A discontinuous lattice (an interior knot of
// multiplicity above the degree) is refused with an input Error naming `source`.
Lattice elevateLattice(const Lattice& lattice, std::array<int, 3> by, const std::string& source = "elevate",
                       uint64_t memoryLimit = 0);

struct LatticeReadOptions {
  std::array<int, 3> npyDegree{2, 2, 2};   // .npy files carry no degree
  // .npy files carry no box: the box is the bounding box of the mesh normalised by the caller
  // (--normalize, 0.99 by default). Required for .npy.
  bool haveMeshBox = false;
  glm::dvec3 meshBoxLo{0.0}, meshBoxHi{0.0};
  // Bytes of host memory the lattice may need to be evaluated (control points, per-knot-box Bezier
  // form, kernel form); a larger one is refused before anything is allocated. 0: physical memory
  // (or the container's limit when lower).
  uint64_t memoryLimit = 0;
};

// Reads by extension: .json (native), .prm (PyGeM), .npy (an array of control points). Throws an
// input Error ("file:line: what") on a bad file.
Lattice readLattice(const std::string& path, const LatticeReadOptions& options = {});

// Writes the format the extension names: .json (native, everything), .npy (the control points only, an
// array (mu, mv, mw, 3) of float64, read back with the .npy conventions) or .prm (PyGeM's: only a
// lattice of one Bezier box on a rotated rectangular box; points outside are then left unmoved) or .vtk
// (the control net as a legacy VTK structured grid for ParaView, with each point's displacement from the
// identity; written only, not read).
// Throws an input Error for another extension or a lattice the format cannot hold.
void writeLattice(const std::string& path, const Lattice& lattice);

// Writes the native JSON format (shortest digits that read back to the same doubles) to a temporary
// file renamed into place.
void writeLatticeJson(const std::string& path, const Lattice& lattice);

// PyGeM's FFD parameters as a .prm file holds them (mathLab/PyGeM pygem/ffd.py): counts[a] control
// points (degree counts[a] - 1) on the box origin + R diag(length) [0,1]^3, R = Rx Ry Rz of the angles
// in degrees, point (i, j, k) displaced by mu (box-length units, the box's axes). What the Python
// package's sffd.FFD holds; readLattice of a .prm file is pygemLattice(readPygemParameters(path)).
struct PygemParameters {
  std::array<int, 3> counts{2, 2, 2};   // 2..6 (degree 1..5)
  glm::dvec3 length{1.0}, origin{0.0}, angleDeg{0.0};
  std::vector<glm::dvec3> mu;   // counts[0]*counts[1]*counts[2], indexed as Lattice::index; empty: all 0
};

// Reads a .prm file whatever its name; an input Error ("file:line: what") on a bad one.
PygemParameters readPygemParameters(const std::string& path);
// Writes every mu (PyGeM's layout), to a temporary file renamed into place.
void writePygemParameters(const std::string& path, const PygemParameters& parameters);
// The lattice the parameters mean (OutsideMode::Keep); an input Error for bad parameters.
Lattice pygemLattice(const PygemParameters& parameters);

}  // namespace sffd
