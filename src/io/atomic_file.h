// Output files appear whole or not at all: written to a temporary file beside the target, then renamed.
#pragma once
#include <functional>
#include <ostream>
#include <string>

namespace sffd {

// Calls write(stream) on a temporary file in the target's folder and renames it to `path` when
// write returns and the stream is good. On any failure the temporary file is removed and an Error
// is thrown (kind Input for an unwritable path).
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write,
                         bool binary = false);

// For writers that need a file name (OpenMesh): the temporary path is passed to write(tmpPath).
void writePathAtomically(const std::string& path, const std::function<void(const std::string&)>& write);

}  // namespace sffd
