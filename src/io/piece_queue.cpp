#include "io/piece_queue.h"

#include <system_error>

namespace sffd {

PieceQueue::PieceQueue(std::function<void(const Mesh&)> write) : write_(std::move(write)) {
  try {
    thread_ = std::thread([this] { run(); });
  } catch (const std::system_error&) {   // no thread to be had: push() writes on the caller's
  }
}

PieceQueue::~PieceQueue() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    waiting_.clear();
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void PieceQueue::push(const Mesh& piece) {
  if (!threaded()) return write_(piece);
  Mesh copy;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return waiting_.size() < kWaiting || error_; });
    if (error_) std::rethrow_exception(error_);
    if (!spare_.empty()) copy = std::move(spare_.back()), spare_.pop_back();
  }
  // assign() into the spare's storage: no allocation (nor page faults) once the pieces stop growing.
  copy.positions.assign(piece.positions.begin(), piece.positions.end());
  copy.normals.assign(piece.normals.begin(), piece.normals.end());
  copy.texcoords.assign(piece.texcoords.begin(), piece.texcoords.end());
  copy.colors.assign(piece.colors.begin(), piece.colors.end());
  copy.triangles.assign(piece.triangles.begin(), piece.triangles.end());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    waiting_.push_back(std::move(copy));
  }
  changed_.notify_all();
}

void PieceQueue::drain() {
  if (threaded()) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return (waiting_.empty() && !writing_) || error_; });
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  if (error_) std::rethrow_exception(error_);
}

void PieceQueue::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return stop_ || !waiting_.empty(); });
    if (waiting_.empty()) return;   // stopped
    Mesh piece = std::move(waiting_.front());
    waiting_.pop_front();
    writing_ = true;
    lock.unlock();
    changed_.notify_all();   // room for the producer
    std::exception_ptr failed;
    try {
      write_(piece);
    } catch (...) {
      failed = std::current_exception();
    }
    lock.lock();
    writing_ = false;
    spare_.push_back(std::move(piece));
    if (failed) error_ = failed, waiting_.clear();
    changed_.notify_all();
    if (error_) return;   // the rest is dropped; push() and drain() report it
  }
}

}  // namespace sffd
