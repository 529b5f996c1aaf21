// libFuzzer target: the text mesh readers (.obj, .off, .bpt, ASCII .ply and .stl) on the same bytes,
// through readMeshBytes, i.e. exactly as `sffd deform FILE` reads a file of that extension.
#include "fuzz_common.h"
#include "io/mesh_io_internal.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (const char* name : {"fuzz.obj", "fuzz.off", "fuzz.bpt", "fuzz.ply", "fuzz.stl"}) {
    sffd::MeshReadOptions options;
    options.bptResolution = 4;   // keeps a many-patch .bpt cheap; the tessellation code is the same
    sffd::fuzz::expectReadOrInputError([&] { sffd::fuzz::checkMesh(sffd::meshio::readMeshBytes(name, bytes, options)); });
  }
  return 0;
}
