#include "io/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <unistd.h>

#include <sffd/error.h>

namespace sffd {
namespace fs = std::filesystem;

namespace {
std::string temporaryBeside(const std::string& path) {
  fs::path p(path);
  std::random_device rd;
  std::string name = "." + p.filename().string() + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(rd() % 1000000);
  // Keep the extension last: writers that dispatch on it (OpenMesh) still see it.
  name += p.extension().string();
  return (p.parent_path() / name).string();
}

void commit(const std::string& tmp, const std::string& path) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    int e = errno;
    std::remove(tmp.c_str());
    throw inputError(path, 0, std::string("cannot write: ") + std::strerror(e));
  }
}
}  // namespace

void writePathAtomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  if (fs::is_directory(path)) throw inputError(path, 0, "cannot write: is a directory");
  std::string tmp = temporaryBeside(path);
  {
    std::ofstream probe(tmp, std::ios::binary);
    if (!probe) throw inputError(path, 0, std::string("cannot write: ") + std::strerror(errno));
  }
  try {
    write(tmp);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  std::error_code ec;
  if (!fs::exists(tmp, ec) || fs::file_size(tmp, ec) == 0) {
    std::remove(tmp.c_str());
    throw Error(ErrorKind::Internal, path + ": writer produced no data");
  }
  commit(tmp, path);
}

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write, bool binary) {
  writePathAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
    if (!out) throw inputError(path, 0, std::string("cannot write: ") + std::strerror(errno));
    write(out);
    out.flush();
    if (!out) throw inputError(path, 0, "cannot write: write failed (disk full?)");
  });
}

}  // namespace sffd
