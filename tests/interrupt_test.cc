// An interrupted run leaves nothing behind: SIGINT, SIGTERM or SIGHUP while the output is being
// written removes the temporary file, the output never appears half-written, and the file it would
// replace is as it was (kept aside meanwhile: put back, and nothing of that left either).
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "tests/support/cli_runner.h"

namespace sffd::test {
namespace {

bool hasTemporary(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp") != std::string::npos) return true;
  return false;
}

class Interrupt : public ::testing::TestWithParam<int> {};

TEST_P(Interrupt, RemovesTheTemporaryOutput) {
  const int sig = GetParam();
  fs::path dir = tempDir("interrupt_" + std::to_string(sig));
  const std::string lattice = (dir / "l.json").string(), out = (dir / "out.obj").string();
  ASSERT_EQ(runSffd("lattice " + std::string(SFFD_TEST_DATA) + "/sphere.obj -o " + lattice + " --preset twist:0.3 --quiet").status, 0);
  // A job whose output takes a second or more to write (about 150 MB of OBJ).
  const std::string mesh = std::string(SFFD_TEST_DATA) + "/sphere.obj";
  std::ofstream(out) << "the user's out.obj";
  pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    // As from a terminal: the test runner may have started us with these signals ignored.
    for (int s : {SIGINT, SIGTERM, SIGHUP}) ::signal(s, SIG_DFL);
    ::execl(SFFD_BINARY, SFFD_BINARY, "deform", mesh.c_str(), "-l", lattice.c_str(), "--backend", "cpu", "--tess", "30",
            "-o", out.c_str(), "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  bool seen = false;
  for (int i = 0; i < 3000 && !seen; ++i) {   // up to a minute
    seen = hasTemporary(dir);
    if (!seen) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, sig);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(seen) << "the temporary output never appeared";
  // Killed by the signal it was sent: the handler re-raises it after the clean-up.
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run ended before the signal arrived";
  EXPECT_EQ(WTERMSIG(status), sig);
  EXPECT_EQ(slurp(out), "the user's out.obj");
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_TRUE(e.path() == lattice || e.path() == out) << "left " << e.path();
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Signals, Interrupt, ::testing::Values(SIGINT, SIGTERM, SIGHUP),
                         [](const ::testing::TestParamInfo<int>& i) {
                           return std::string(i.param == SIGINT ? "SIGINT" : i.param == SIGTERM ? "SIGTERM" : "SIGHUP");
                         });

}  // namespace
}  // namespace sffd::test
