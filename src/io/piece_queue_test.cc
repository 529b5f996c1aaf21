// PieceQueue (piece_queue.h): pieces written in order on its thread, copies independent of the caller's
// piece, a write's error reported by the next push() or drain(), a queue dropped before it drains, and
// one that gets no thread.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
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

// The child's part of the test below: 0 when the queue, without a thread, wrote as it should.
int writeWithoutAThread() {
  long pages = 0;
  FILE* statm = std::fopen("/proc/self/statm", "r");
  if (!statm || std::fscanf(statm, "%ld", &pages) != 1) return 3;
  std::fclose(statm);
  // 2 MiB above what the process maps: a thread's stack (8 MiB by default) does not fit.
  const rlim_t limit = rlim_t(pages) * 4096 + (2u << 20);
  const rlimit rl{limit, limit};
  if (setrlimit(RLIMIT_AS, &rl) != 0) return 4;
  std::vector<size_t> ids;
  bool elsewhere = false;
  const std::thread::id caller = std::this_thread::get_id();
  PieceQueue q([&](const Mesh& m) {
    if (m.positions[0].x == 7) throw std::runtime_error("disk full");
    ids.push_back(size_t(m.positions[0].x));
    elsewhere = elsewhere || std::this_thread::get_id() != caller;
  });
  if (q.threaded()) return 5;
  for (size_t i = 0; i < 7; ++i) q.push(pieceOf(i, 3));
  bool thrown = false;
  try {
    q.push(pieceOf(7, 3));
  } catch (const std::runtime_error&) {
    thrown = true;
  }
  q.drain();
  return thrown && !elsewhere && ids == std::vector<size_t>{0, 1, 2, 3, 4, 5, 6} ? 0 : 6;
}

// Without a thread to be had (here: no address space for its stack), the pieces are written on the
// caller's thread, in order, and a write's error comes out of that push(). In a child process: the
// limit would hold the whole test program.
TEST(PieceQueue, WithoutAThreadWritesOnTheCallers) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's shadow memory does not live under an address-space limit";
#endif
  // A fresh process: a forked one could take a stack glibc kept from the other tests' threads.
  ::testing::FLAGS_gtest_death_test_style = "threadsafe";
  EXPECT_EXIT(std::_Exit(writeWithoutAThread()), ::testing::ExitedWithCode(0), "");
}

}  // namespace
