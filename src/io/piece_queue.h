// A streamed file's pieces written on a thread of their own (MeshFileWriter), so that the producer (the
// weld of a result) goes on making the next piece while the last ones are formatted and written: the
// whole run waits for the slower of the two, not for their sum (docs/performance/whole_run.md "The file
// written beside the weld").
#pragma once
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include <sffd/mesh.h>

namespace sffd {

class PieceQueue {
 public:
  // At most this many pieces wait to be written; push() waits for room. A piece is a copy of the
  // producer's (its storage reused from piece to piece), so what the queue holds stays bounded.
  static constexpr size_t kWaiting = 4;

  // `write` runs on the queue's thread, one piece at a time, in the order pushed.
  explicit PieceQueue(std::function<void(const Mesh&)> write);
  // Stops the thread; pieces not yet written are dropped (the file is abandoned).
  ~PieceQueue();
  PieceQueue(const PieceQueue&) = delete;
  PieceQueue& operator=(const PieceQueue&) = delete;

  // Whether the queue got its thread. Without one (none to be had), push() writes on the caller's.
  bool threaded() const { return thread_.joinable(); }
  // Copies what a file of `piece` holds (positions, normals, texture coordinates, colours, triangles) for
  // the thread. Throws what `write` threw for an earlier piece (the pieces after that one are dropped).
  void push(const Mesh& piece);
  // Waits until every piece pushed is written and ends the thread; rethrows write's exception.
  void drain();

 private:
  void run();
  std::function<void(const Mesh&)> write_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Mesh> waiting_;
  std::vector<Mesh> spare_;   // written pieces, their storage kept for the next copies
  bool writing_ = false, stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;   // last: started once the rest exists
};

}  // namespace sffd
