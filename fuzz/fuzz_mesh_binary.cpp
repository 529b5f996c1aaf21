// libFuzzer target: the binary mesh readers (.ply binary_little/big_endian, binary .stl, glTF .glb and
// .gltf (its JSON), OpenMesh .om)
// on the same bytes, through readMeshBytes. The .om reader runs OpenMesh in a forked child (a crash
// there is reported as a damaged file); here it runs only for bytes that start with "OM", so that the
// other readers keep their speed.
#include "fuzz_common.h"
#include "io/mesh_io_internal.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (const char* name : {"fuzz.ply", "fuzz.stl", "fuzz.glb", "fuzz.gltf"})
    sffd::fuzz::expectReadOrInputError([&] { sffd::fuzz::checkMesh(sffd::meshio::readMeshBytes(name, bytes)); });
  if (size >= 2 && data[0] == 'O' && data[1] == 'M')
    sffd::fuzz::expectReadOrInputError([&] { sffd::fuzz::checkMesh(sffd::meshio::readMeshBytes("fuzz.om", bytes)); });
  return 0;
}
