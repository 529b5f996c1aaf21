#include "io/atomic_file.h"

#include <atomic>
#include <climits>
#include <csignal>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <sffd/error.h>

namespace sffd {
namespace fs = std::filesystem;

namespace {

// What the handler of SIGINT, SIGTERM and SIGHUP undoes so that an interrupted run leaves nothing behind:
// the temporary files being written (the first kTemporarySlots), then a command's outputs (OutputUndo, the
// others). Fixed storage: the handler may only call async-signal-safe functions (unlink, rename, signal,
// raise) and read plain memory.
constexpr int kTemporarySlots = 16, kSlots = kTemporarySlots + 64;
constexpr size_t kPathMax = 4096;
char gPath[kSlots][kPathMax], gAside[kSlots][kPathMax];
volatile std::sig_atomic_t gUsed[kSlots];
std::mutex gSlotMutex;

// One output undone: a file made removed, or the file it replaced, kept at `aside`, renamed back over it.
// Twice is as once. A rename between two links to one file does nothing: where the file was never replaced,
// its second name goes.
void undoOutput(const char* path, const char* aside) {
  if (!*aside) {
    ::unlink(path);
    return;
  }
  ::rename(aside, path);
  ::unlink(aside);
}

extern "C" void undoAndDie(int sig) {
  for (int i = kSlots; i-- > 0;)   // the latest first (slots are taken in order): a file replaced twice gets its first contents back
    if (gUsed[i]) undoOutput(gPath[i], gAside[i]);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

// Installs the handler once, for each signal whose disposition is still the default: an application
// that handles a signal itself keeps its handler (and its own clean-up).
void installInterruptHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_DFL) {
        struct sigaction sa {};
        sa.sa_handler = undoAndDie;
        sigemptyset(&sa.sa_mask);
        ::sigaction(sig, &sa, nullptr);
      }
    }
  });
}

// Registers `path` (and `aside`) for the handler in a free slot of [from, to); a path too long or no slot
// free: not registered (still undone on every failure the program sees). The slot, or -1.
int claimSlot(const std::string& path, const std::string& aside, int from, int to) {
  installInterruptHandlers();
  if (path.size() >= kPathMax || aside.size() >= kPathMax) return -1;
  std::lock_guard<std::mutex> lock(gSlotMutex);
  for (int i = from; i < to; ++i)
    if (!gUsed[i]) {
      std::memcpy(gPath[i], path.c_str(), path.size() + 1);
      std::memcpy(gAside[i], aside.c_str(), aside.size() + 1);
      gUsed[i] = 1;
      return i;
    }
  return -1;
}

void releaseSlot(int slot) {
  if (slot < 0) return;
  std::lock_guard<std::mutex> lock(gSlotMutex);
  gUsed[slot] = 0;
}

// A temporary path registered for the handler while it exists.
class TemporaryGuard {
 public:
  explicit TemporaryGuard(const std::string& path) : slot_(claimSlot(path, "", 0, kTemporarySlots)) {}
  ~TemporaryGuard() { releaseSlot(slot_); }
  TemporaryGuard(const TemporaryGuard&) = delete;
  TemporaryGuard& operator=(const TemporaryGuard&) = delete;

 private:
  int slot_;
};

std::string temporaryBeside(const std::string& path) {
  fs::path p(path);
  std::random_device rd;
  // The count keeps several temporaries of one target apart within a process (MeshFileWriter's scratch files).
  static std::atomic<unsigned> count{0};
  const std::string tag = ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(rd() % 1000000) + "_" + std::to_string(count++);
  // Keep the extension last: writers that dispatch on it (OpenMesh) still see it.
  const std::string ext = p.extension().string();
  // A name has at most NAME_MAX bytes: the temporary keeps as much of the target's as fits, so that every
  // name that can be written can be written through it.
  std::string stem = p.filename().string();
  const size_t fixed = 1 + tag.size() + ext.size();
  if (fixed < NAME_MAX && stem.size() > NAME_MAX - fixed) stem.resize(NAME_MAX - fixed);
  return (p.parent_path() / ("." + stem + tag + ext)).string();
}

// A rename over an existing file makes ext4 (auto_da_alloc) flush the new file's delayed allocation first:
// 7.5-11 ms for the teapot's 18 MB PLY. Its blocks allocated before (fallocate, the size kept), the rename
// takes 1-1.6 ms and the pages are written back later, as any file's (docs/performance/whole_run.md,
// "Output files replaced without a flush"). Best effort: where it is refused, the rename goes as before.
void allocateBeforeReplacing(const std::string& tmp, const std::string& path) {
#if defined(__linux__) && defined(FALLOC_FL_KEEP_SIZE)
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;   // nothing is replaced
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return;
  if (::fstat(fd, &st) == 0 && st.st_size > 0) (void)::fallocate(fd, FALLOC_FL_KEEP_SIZE, 0, st.st_size);
  ::close(fd);
#else
  (void)tmp, (void)path;
#endif
}

// `tmp` renamed onto `file`, the file that `path` names (replacedFile); errors name `path`.
void renameInto(const std::string& tmp, const std::string& file, const std::string& path) {
  allocateBeforeReplacing(tmp, file);
  if (std::rename(tmp.c_str(), file.c_str()) != 0) {
    int e = errno;
    std::remove(tmp.c_str());
    throw inputError(path, 0, std::string("cannot write: ") + std::strerror(e));
  }
}

}  // namespace

// A rename onto the link itself would replace the link and leave its target as it was.
std::string replacedFile(const std::string& path) {
  std::error_code ec;
  fs::path p = path;
  for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(p, ec)); ++hops) {
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) return path;
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  return p.string();
}

void writePathAtomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  std::error_code ec;   // a path the system refuses (a name too long) is found by the open below, with its reason
  if (fs::is_directory(path, ec)) throw inputError(path, 0, "cannot write: is a directory");
  const std::string file = replacedFile(path);
  std::string tmp = temporaryBeside(file);
  TemporaryGuard guard(tmp);   // registered before the file exists, released after rename or removal
  {
    std::ofstream probe(tmp, std::ios::binary);
    if (!probe) throw inputError(path, 0, std::string("cannot write: ") + std::strerror(errno));
  }
  // `write` makes the file anew: opened again with O_TRUNC, the empty file would count for ext4 as one
  // replaced by truncation, whose blocks it allocates and flushes at close (auto_da_alloc).
  std::remove(tmp.c_str());
  try {
    write(tmp);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  if (!fs::exists(tmp, ec) || fs::file_size(tmp, ec) == 0) {
    std::remove(tmp.c_str());
    throw Error(ErrorKind::Internal, path + ": writer produced no data");
  }
  renameInto(tmp, file, path);
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

struct AtomicFile::Impl {
  std::string path, file, tmp;   // as asked for, the file it names (replacedFile), the temporary beside that
  TemporaryGuard guard;          // registered before the file exists, released after rename or removal
  std::ofstream out;
  bool committed = false;
  Impl(const std::string& p, std::string f) : path(p), file(std::move(f)), tmp(temporaryBeside(file)), guard(tmp) {}
};

AtomicFile::AtomicFile(const std::string& path, bool binary) {
  std::error_code ec;   // as in writePathAtomically
  if (fs::is_directory(path, ec)) throw inputError(path, 0, "cannot write: is a directory");
  impl_ = std::make_unique<Impl>(path, replacedFile(path));
  impl_->out.open(impl_->tmp, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
  if (!impl_->out) throw inputError(path, 0, std::string("cannot write: ") + std::strerror(errno));
}

AtomicFile::~AtomicFile() {
  if (impl_->committed) return;
  impl_->out.close();
  std::remove(impl_->tmp.c_str());
}

std::ostream& AtomicFile::stream() { return impl_->out; }
const std::string& AtomicFile::temporaryPath() const { return impl_->tmp; }

void AtomicFile::commit() {
  impl_->out.flush();
  if (!impl_->out) throw inputError(impl_->path, 0, "cannot write: write failed (disk full?)");
  impl_->out.close();
  if (!impl_->out) throw inputError(impl_->path, 0, "cannot write: write failed (disk full?)");
  impl_->committed = true;
  renameInto(impl_->tmp, impl_->file, impl_->path);   // removes the temporary file itself when the rename fails
}

OutputUndo::OutputUndo(std::string path, std::string aside, bool onInterrupt)
    : path_(std::move(path)), aside_(std::move(aside)), slot_(onInterrupt ? claimSlot(path_, aside_, kTemporarySlots, kSlots) : -1) {}

OutputUndo::OutputUndo(OutputUndo&& o) noexcept
    : path_(std::move(o.path_)), aside_(std::move(o.aside_)), slot_(std::exchange(o.slot_, -1)) {}

OutputUndo::~OutputUndo() { releaseSlot(slot_); }

void OutputUndo::undo() const { undoOutput(path_.c_str(), aside_.c_str()); }

}  // namespace sffd
