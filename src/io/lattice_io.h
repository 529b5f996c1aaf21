// Lattice files (.json native, PyGeM .prm, .npy) and the presets of `sffd lattice`: declared in
// <sffd/lattice.h>, implemented in lattice_io.cpp and lattice_io_formats.cpp.
#pragma once
#include "model/lattice.h"
