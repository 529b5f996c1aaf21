// sffd/deformer.h: one object for every method. A Deformer prepares a mesh for a lattice's
// structure once on a device (for smooth FFD: PN triangles and the split into near-regular
// sub-triangles, kept on the device), then deform() bends it for the lattice's current control
// points as often as asked, uploading only the lattice.
//
//   sffd::Device device = sffd::Device::open();
//   sffd::Mesh mesh = sffd::readMesh("model.obj");
//   sffd::Lattice lattice = sffd::fitLattice(mesh);
//   sffd::Deformer deformer(device, mesh, lattice, {.method = sffd::Method::Smooth, .edgeLength = 0.05});
//   lattice.controlPoints[7].z += 0.2;
//   deformer.deform(lattice);
//   sffd::writeMesh("out.obj", deformer.result());
//
// Methods (docs/METHOD.md):
//   Smooth    the improved smooth FFD: every triangle split into near-regular sub-triangles, each a
//             cubic triangular Bezier patch fitted to the exactly deformed surface, with a deformed
//             normal field, creases kept sharp, tessellated at level `tess`.
//   Accurate  the exact image: knot-box sub-triangles as triangular Bezier patches of degree
//             nu+nv+nw (the reference the other methods are measured against).
//   Classic   vertices and normals only, the input's topology kept (as PyGeM and Blender do).
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <sffd/device.h>
#include <sffd/lattice.h>
#include <sffd/mesh.h>

namespace sffd {

enum class Method { Smooth, Accurate, Classic };
enum class Clip { Regular, KnotBox };        // sub-triangle clipping of smooth FFD (accurate: always KnotBox)
enum class Precision { Auto, Float, Double };  // Auto: double for Classic and Accurate where the device has it

// What a progress callback is told: the stage ("prepare", "pn", "clip", "deform", "download") and
// the fraction of the whole call done, 0..1. Returning false cancels: the call throws an Error of
// kind ErrorKind::Cancelled and the Deformer stays usable for the work already done before it.
struct Progress {
  const char* stage = "";
  double fraction = 0;
};
using ProgressCallback = std::function<bool(const Progress&)>;

struct DeformOptions {
  Method method = Method::Smooth;
  Clip clip = Clip::Regular;
  double edgeLength = 0;         // the paper's l, in model units; 0: a tenth of the mesh's largest extent
  int tess = 10;                 // tessellation level of each patch, 1..64 (66 vertices, 100 triangles at 10)
  int samples = 0;               // smooth: sampling density s of the fit, 0..15; 0: nu+nv+nw (at least 3, as 1 and 2)
  bool strict = false;           // strict kernels: bit-identical on every device, the CPU included
  Precision precision = Precision::Auto;
  bool split = false;            // smooth: the deform step as four dispatches (per-step timings)
  double creaseAngleDeg = kCreaseAngleAuto;  // smooth, meshes without normals: dihedral angle 0..180 above which
                                             // an edge is a crease, or kCreaseAngleAuto (<sffd/mesh.h>)
  uint64_t memoryLimit = 0;      // bytes of host memory a job may plan for (every method); 0: physical memory
  size_t maxChunkElements = 0;   // 0: chunks as large as the device allows (smaller only to test chunking)
  ProgressCallback progress;     // called during long work; may be empty
  // A one-shot job, deformed and its result taken once (as `sffd deform` does): what only a repeated call
  // needs is never kept, so a large job's peak memory is lower. Smooth (either clipping): deform() only
  // takes the lattice, and result() or streamResult() runs the pre-compute, the clipping and the deform
  // stage a few parents at a time, each chunk's records and output done with once welded (timings() and
  // subTriangles() are then the run's; deviceOutput() is empty, patchControlPoints() throws). Accurate:
  // deform() only takes the lattice, and the result runs the kernels a chunk at a time in one device buffer
  // (timings() are then the run's; deviceOutput() is empty). Every method: a second deform(), or a second
  // result() or streamResult(), throws an input Error; so does a result() or streamResult() after one that
  // was cancelled or threw, since what the result is made from is freed as it is made.
  bool once = false;
};

// Times of the last call. GPU time where the device measures it, else host wall time.
struct Timings {
  double pnMs = 0, clipMs = 0, deformMs = 0;
  double wallMs = 0;                                    // the whole call, waiting included
  double weldMs = 0;   // the last result() or streamResult() (smooth, accurate): host time making the patch
                       // vertices from the device's output and welding them (a sink's pieces handed on included)
  std::vector<std::pair<std::string, double>> steps;   // the last deform()'s dispatches by label (split: deform.sample, ...)
};

// One chunk of a Deformer's results on the device, as the interop headers hand it out
// (sffd::vulkan::bufferOf, sffd::opengl::bufferOf). Layout: see Deformer::deviceOutput().
struct OutputChunk {
  size_t first = 0, count = 0;   // Smooth, Accurate: the patches [first, first + count); Classic: the vertices
  uint32_t buffer = 0;           // internal id; see the interop headers
  uint64_t offset = 0, bytes = 0;
};

class Deformer {
 public:
  // Prepares `mesh` for lattices with the structure of `lattice` (degrees, counts, knots, frame) on
  // `device`, which must outlive the Deformer (it may be moved meanwhile: the Deformer follows it).
  // A Mesh is checked as meshFromView checks a view (<sffd/mesh.h> says what each field must hold): a
  // field of the wrong size, an index out of range or a non-finite position or normal is an input Error
  // naming the field and its first bad element; empty normals or weldId are made as readMesh makes them.
  // Throws an input Error for bad options or a mesh that cannot be deformed, a device Error when the
  // device refuses the work. A moved-from Deformer throws an input Error from every call but destruction
  // and assignment.
  Deformer(Device& device, const Mesh& mesh, const Lattice& lattice, const DeformOptions& options = {});
  Deformer(Device& device, const MeshView& mesh, const Lattice& lattice, const DeformOptions& options = {});
  Deformer(Deformer&&) noexcept;
  Deformer& operator=(Deformer&&) noexcept;
  ~Deformer();

  // Deforms with the lattice's current control points; an input Error if its structure differs
  // from the one the Deformer was made for or a control point is not finite. The results below are those
  // of the last call: before the first, or after one that was cancelled or threw for any reason (a refused
  // lattice included), result(), streamResult() and patchControlPoints() throw an input Error and
  // deviceOutput() is empty until a deform() succeeds. The one exception: a one-shot Deformer's second
  // deform() is refused before it touches anything, and the first one's result is still there to take.
  const Timings& deform(const Lattice& lattice);
  // Times of the preparation (pn, clip) and of the last deform().
  const Timings& timings() const;

  // The result as `sffd deform` writes it: Smooth and Accurate, the tessellated patches with shared
  // boundary vertices welded (a closed input gives a closed output); Classic, the input's vertices
  // moved, their normals mapped, its topology kept. Downloaded on each call.
  Mesh result() const;
  // result() handed to `sink` in pieces as it is made (MeshSink, <sffd/mesh.h>: begin(), the pieces, end()),
  // for a result too large to hold twice: Smooth and Accurate weld each chunk as it is downloaded and hand
  // over its vertices and triangles, keeping only what later chunks weld against; Classic hands over its
  // result in one piece. The pieces appended are result(), bit for bit. With sffd::MeshFileWriter the
  // result goes to a file as writeMesh would write it:
  //   sffd::MeshFileWriter out("big.ply", {.binary = true});
  //   deformer.streamResult(out);
  void streamResult(MeshSink& sink) const;
  // Smooth: per sub-triangle 20 control points (x, y, z, 0) x 4 doubles: 10 of the geometry patch,
  // then 10 of the normal patch, in the order docs/METHOD.md gives (what `deform --patches` writes).
  std::vector<double> patchControlPoints() const;
  size_t subTriangles() const;   // Smooth, Accurate: the patches made; Classic: 0

  // The last deform()'s output where it lives on the device, for drawing from it without a copy; 4
  // reals (float, or double when doublePrecision()) a position or unit normal, w = 0 unless said.
  //   Smooth    per patch of the chunk, tessVertexCount(tess) positions then as many normals.
  //   Accurate  the positions of the chunk's patches' vertices (tessVertexCount(tess) a patch), then
  //             from offset + bytes / 2 their normals.
  //   Classic   per vertex a position (w: 1 inside the lattice box, 0 outside), then from
  //             offset + bytes / 2 the normals.
  // Empty on a device that keeps nothing (the CPU reference). Positions there are local: a world
  // position is local / localScale() + localOrigin().
  std::vector<OutputChunk> deviceOutput() const;
  // The frame the devices compute in: local = (world - localOrigin()) * localScale(), on the host in
  // double before any device sees mesh or lattice, and every result but deviceOutput() moved back, so
  // float precision does not depend on where a model sits nor its thresholds on its size.
  // localOrigin(): the lattice box's centre rounded to a power of two 8 to 16 times the box's size, so 0
  // unless the box lies several times its size away from the world origin. localScale(): a power of two
  // (exact), 1 unless the box is smaller than 2^-8 or at least 2^12 across, else the one that makes it 1
  // to 2 across.
  glm::dvec3 localOrigin() const;
  double localScale() const;
  bool doublePrecision() const;   // whether the reals above are doubles
  // Significant digits that keep every value of result() in a text file (MeshWriteOptions, as `sffd
  // deform` writes): 17 for double results, or float ones computed around a localOrigin() away from 0
  // (their float bits are relative to it, docs/ROBUSTNESS.md); else 9.
  int resultDigits() const;
  const DeformOptions& options() const;
  Device& device() const;

  struct Impl;
  Impl& internal();   // for the command-line tool's analysis; not part of the stable API

 private:
  std::unique_ptr<Impl> impl_;
  Impl& impl() const;   // an input Error on a moved-from Deformer
};

// Vertices and triangles of one patch tessellated at level L: (L+1)(L+2)/2 and L^2. L is a level
// DeformOptions::tess takes, 1..64; an input Error outside it.
int tessVertexCount(int level);
int tessTriangleCount(int level);

}  // namespace sffd
