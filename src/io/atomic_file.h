// Output files appear whole or not at all: written to a temporary file beside the target, then renamed.
// A target that is a symbolic link is written through: the file at the end of the link gets the new
// contents (the temporary beside it), and the link stays.
#pragma once
#include <functional>
#include <memory>
#include <ostream>
#include <string>

namespace sffd {

// Calls write(stream) on a temporary file in the target's folder and renames it to `path` when
// write returns and the stream is good. On any failure the temporary file is removed and an Error
// is thrown (kind Input for an unwritable path).
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write,
                         bool binary = false);

// The file a write to `path` replaces: `path`, or where it is a symbolic link the file at the end of its
// chain (which need not exist yet). A writer whose file names another beside it (a .gltf's NAME.bin) names
// the one beside this file.
std::string replacedFile(const std::string& path);

// For writers that need a file name (OpenMesh): the temporary path is passed to write(tmpPath).
void writePathAtomically(const std::string& path, const std::function<void(const std::string&)>& write);

// The same for a writer that is handed its data in pieces: the temporary file is opened by the constructor
// (an input Error for an unwritable path, as above), written through stream(), and renamed to `path` by
// commit(); destroyed uncommitted (an exception), it is removed. Never committed, it is a scratch file
// beside `path` (readable at temporaryPath() once flushed) that goes with the object.
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path, bool binary = true);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  std::ostream& stream();
  const std::string& temporaryPath() const;
  // Flushes and checks the stream (an input Error for a failed write, e.g. a full disk), then renames.
  void commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One output of a command that writes several, undone when the command fails (undo()) or, with
// `onInterrupt`, is interrupted (SIGINT, SIGTERM, SIGHUP: by the handler that removes the temporary files,
// while this is held, the latest first): the file made at `path` removed, or, where `aside` names the file it
// replaced (kept there: a second link to it, or the file moved), that put back. At most 64 held at once are
// undone by an interrupt.
class OutputUndo {
 public:
  OutputUndo(std::string path, std::string aside, bool onInterrupt);
  OutputUndo(OutputUndo&& o) noexcept;
  OutputUndo& operator=(OutputUndo&&) = delete;
  ~OutputUndo();   // undoes nothing
  void undo() const;
  const std::string& aside() const { return aside_; }

 private:
  std::string path_, aside_;
  int slot_;
};

}  // namespace sffd
