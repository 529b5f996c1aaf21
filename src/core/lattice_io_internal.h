// Internal interface of the lattice readers (lattice_io*.cpp): each gets the file's bytes.
#pragma once
#include <string>

#include "lattice_io.h"

namespace sffd::latticeio {

Lattice readJson(const std::string& path, const std::string& text);
Lattice readPrm(const std::string& path, const std::string& text);
Lattice readNpy(const std::string& path, const std::string& text, const LatticeReadOptions& options);

// Most control points a lattice file may ask for (checked before anything is allocated).
constexpr size_t kMaxControlPoints = size_t(1) << 24;

}  // namespace sffd::latticeio
