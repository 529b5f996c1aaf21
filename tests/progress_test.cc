// The progress line on stderr (apps/sffd/progress_line.h): drawn with \r and erased for work longer
// than about a second when stderr is a terminal, never otherwise (a pipe, a file, --quiet).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>

#include "support/cli_runner.h"

namespace {

using namespace sffd::test;

// About two seconds on the CPU reference (4.9 million output triangles), nearly all of it the
// work the line reports: the file is a binary PLY, whose write is short (a text file's write, after
// the line is erased, made the job long enough not to be skipped below with too little work before it).
std::string longJob(const fs::path& dir) {
  const std::string data = SFFD_TEST_DATA;
  return "deform " + data + "/torus.obj -l " + data + "/lattices/torus_twist.npy --backend cpu --edge-length 0.02 --tess 8 -o " +
         (dir / "out.ply").string() + " --binary";
}

TEST(Progress, NothingWhenStderrIsNotATerminal) {
  const fs::path dir = tempDir("progress_pipe");
  RunResult r = runSffd(longJob(dir));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('%'), std::string::npos) << r.err;
}

TEST(Progress, OneLineRedrawnAndErasedOnATerminal) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1) for a pseudo-terminal";
  const fs::path dir = tempDir("progress_tty");
  const fs::path log = dir / "tty.txt";
  // script(1) runs the command on a pseudo-terminal and copies what it wrote there to stdout.
  for (const char* quiet : {"", " --quiet"}) {
    const std::string cmd = bounded("script -qec '" + std::string(SFFD_BINARY) + " " + longJob(dir) + quiet + "' /dev/null") + " > " + log.string();
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const std::string tty = slurp(log);
    if (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(1500))
      GTEST_SKIP() << "the job took less than the line's second of grace here";
    if (*quiet) {
      EXPECT_EQ(tty.find('%'), std::string::npos) << tty;
      continue;
    }
    const size_t shown = tty.find("\rsffd: ");
    ASSERT_NE(shown, std::string::npos) << tty;
    EXPECT_NE(tty.find('%', shown), std::string::npos) << tty;
    // Erased (blanks, then \r) before the note that follows it.
    const size_t note = tty.find("sffd: wrote");
    ASSERT_NE(note, std::string::npos) << tty;
    EXPECT_EQ(tty.substr(note - 2, 2), " \r") << tty;
  }
}

}  // namespace
