// libFuzzer target: the lattice readers (native JSON, PyGeM .prm, .npy) on the same bytes, through
// readLatticeBytes as `sffd deform -l FILE` reads them. An accepted lattice must validate, and a small
// one is packed for the kernels and checked for fold-over, as `sffd deform` does next.
#include "fuzz_common.h"
#include "model/lattice_fold.h"
#include "io/lattice_io_internal.h"
#include "model/lattice_pack.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  sffd::LatticeReadOptions options;
  options.haveMeshBox = true;   // .npy: the box of a normalised mesh
  options.meshBoxLo = glm::dvec3(-1.0);
  options.meshBoxHi = glm::dvec3(1.0);
  for (const char* name : {"fuzz.json", "fuzz.prm", "fuzz.npy"}) {
    sffd::fuzz::expectReadOrInputError([&] {
      sffd::Lattice L = sffd::latticeio::readLatticeBytes(name, bytes, options);
      sffd::validateLattice(L, name);   // throws an input Error: an accepted lattice must pass it
      for (const auto& p : L.controlPoints)
        if (!sffd::fuzz::finite(p)) sffd::fuzz::fail("non-finite control point accepted");
      // Packing costs O(boxes * points) today (docs/ROBUSTNESS.md, known limits): only small lattices here.
      if (L.pointCount() <= 512) {
        sffd::PackedLattice P = sffd::packLattice(L);
        sffd::FoldCheck c = sffd::checkLatticeFold(P);
        if (c.samples != 27 * c.boxesChecked) sffd::fuzz::fail("fold check sample count");
      }
    });
  }
  return 0;
}
