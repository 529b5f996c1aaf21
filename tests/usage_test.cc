// The command line's own help: --version, and `sffd help CMD` saying exactly what `sffd CMD --help` says.
#include <gtest/gtest.h>

#include <sffd/sffd.h>

#include "tests/support/cli_runner.h"

namespace sffd::test {
namespace {

TEST(Usage, VersionIsTheLibrarysVersion) {
  RunResult r = runSffd("--version");
  EXPECT_EQ(r.status, 0);
  const std::string built = std::to_string(SFFD_VERSION_MAJOR) + "." + std::to_string(SFFD_VERSION_MINOR) + "." +
                            std::to_string(SFFD_VERSION_PATCH);
  EXPECT_EQ(r.out, "sffd " + built + "\n");
  EXPECT_EQ(sffd::version(), built);   // the library's at run time, CMake's package version too (CMakeLists.txt reads sffd.h)
  EXPECT_EQ(std::string(SFFD_PROJECT_VERSION), built);
  // An argument it does not take is named, as every command's is (it was ignored).
  RunResult extra = runSffd("--version extra");
  EXPECT_EQ(extra.status, 2);
  EXPECT_EQ(extra.out, "");
  EXPECT_EQ(extra.err, "sffd: error: unexpected argument 'extra' (usage: sffd --version)\n");
}

TEST(Usage, HelpCommandEqualsTheCommandsHelpOption) {
  for (const char* c : {"deform", "lattice", "devices", "conform", "clip", "error", "render", "bench", "animate", "view"}) {
    RunResult a = runSffd(std::string("help ") + c), b = runSffd(std::string(c) + " --help");
    EXPECT_EQ(a.status, 0) << c;
    EXPECT_FALSE(a.out.empty()) << c;
    EXPECT_EQ(a.out, b.out) << c;
  }
  RunResult all = runSffd("help");
  EXPECT_EQ(all.status, 0);
  EXPECT_EQ(all.out, runSffd("--help").out);
  EXPECT_EQ(runSffd("help help").out, all.out);   // help's own help (it was "unknown command 'help'")
  RunResult bad = runSffd("help nosuch");
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.err, "sffd: error: unknown command 'nosuch' (sffd --help lists them)\n");
}

}  // namespace
}  // namespace sffd::test
