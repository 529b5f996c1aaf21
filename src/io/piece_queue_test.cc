// PieceQueue (piece_queue.h): pieces written in order on its thread, copies independent of the caller's
// piece, a write's error reported by the next push() or drain(), and a queue dropped before it drains.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "io/piece_queue.h"

using namespace sffd;

namespace {

Mesh pieceOf(size_t id, size_t vertices) {
  Mesh m;
  for (size_t v = 0; v < vertices; ++v) m.positions.push_back({double(id), double(v), 0.0});
  m.normals.assign(vertices, {0.0, 0.0, 1.0});
  m.triangles.push_back({uint32_t(id), 0, 0});
  return m;
}

TEST(PieceQueue, WritesCopiesInOrderOnItsThread) {
  std::vector<size_t> ids;
  std::vector<size_t> sizes;
  std::thread::id writer;
  PieceQueue q([&](const Mesh& m) {
    ids.push_back(size_t(m.positions[0].x));
    sizes.push_back(m.positions.size());
    EXPECT_EQ(m.normals.size(), m.positions.size());
    EXPECT_EQ(m.triangles[0][0], ids.back());
    writer = std::this_thread::get_id();
  });
  ASSERT_TRUE(q.threaded());
  Mesh piece;
  for (size_t i = 0; i < 100; ++i) {
    piece = pieceOf(i, 1 + i % 7);   // the caller's piece changes at once: the queue holds copies
    q.push(piece);
  }
  q.drain();
  ASSERT_EQ(ids.size(), 100u);
  for (size_t i = 0; i < 100; ++i) {
    EXPECT_EQ(ids[i], i);
    EXPECT_EQ(sizes[i], 1 + i % 7);
  }
  EXPECT_NE(writer, std::this_thread::get_id());
}

TEST(PieceQueue, WaitsForRoomRatherThanHoldingMorePieces) {
  std::atomic<bool> release{false};
  std::atomic<size_t> written{0};
  PieceQueue q([&](const Mesh&) {
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ++written;
  });
  std::atomic<size_t> pushed{0};
  std::thread producer([&] {
    for (size_t i = 0; i < 3 * PieceQueue::kWaiting; ++i) q.push(pieceOf(i, 3)), ++pushed;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  // One piece in write(), kWaiting waiting: the producer waits for room.
  EXPECT_EQ(pushed.load(), PieceQueue::kWaiting + 1);
  release = true;
  producer.join();
  q.drain();
  EXPECT_EQ(written.load(), 3 * PieceQueue::kWaiting);
}

TEST(PieceQueue, AWritesErrorReachesTheCallerAndStopsTheWrites) {
  size_t written = 0;
  PieceQueue q([&](const Mesh& m) {
    if (m.positions[0].x == 2.0) throw std::runtime_error("disk full");
    ++written;
  });
  bool thrown = false;
  for (size_t i = 0; i < 50 && !thrown; ++i) {
    try {
      q.push(pieceOf(i, 2));
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "disk full");
      thrown = true;
    }
  }
  // Either a later push() or drain() gives it; no piece after the failed one is written.
  try {
    q.drain();
    ADD_FAILURE() << "drain() did not report the error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "disk full");
  }
  EXPECT_EQ(written, 2u);
}

TEST(PieceQueue, DroppedBeforeDrainingWritesNoMore) {
  std::atomic<size_t> written{0};
  {
    PieceQueue q([&](const Mesh&) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      ++written;
    });
    for (size_t i = 0; i < PieceQueue::kWaiting; ++i) q.push(pieceOf(i, 1));
  }   // the destructor stops the thread: at most the piece in hand is written
  EXPECT_LE(written.load(), 1u);
  PieceQueue empty([](const Mesh&) {});
  EXPECT_NO_THROW(empty.drain());
}

}  // namespace
