// sffd: smooth free-form deformation on any GPU. Dispatches to the commands and turns every failure
// into one "sffd: error: ..." line and the documented exit status (docs/CLI.md).
#include <cstdio>
#include <cstring>
#include <new>
#include <string>

#include "apps/sffd/cli.h"
#include "backends/backend_select.h"
#include "core/huge_pages.h"
#include <sffd/sffd.h>

using namespace sffd;

// Every message is one printable line, whatever a file name or a token in it holds (docs/CLI.md).
static std::string oneLine(const char* what) {
  std::string s(what);
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return s;
}

static std::vector<cli::CommandSpec> commands() {
  return {cli::deformCommand(), cli::latticeCommand(), cli::devicesCommand(), cli::conformCommand(), cli::clipCommand(),
          cli::errorCommand(),
          cli::renderCommand(), cli::benchCommand(), cli::animateCommand(),
#if SFFD_WITH_VIEWER
          cli::viewCommand(),
#endif
  };
}

static void usage(FILE* f) {
  std::fprintf(f, "usage: sffd <command> [options]   (sffd help <command> or sffd <command> --help: its options)\n"
                  "       sffd --version\n\ncommands:\n");
  for (const auto& c : commands()) std::fprintf(f, "  %-9s %s\n", c.name, c.summary);
}

int main(int argc, char** argv) {
  sffd::restartWithHugePages(argv);   // docs/performance/whole_run.md "Huge pages for the whole process"
  try {
    if (argc < 2) throw Error(ErrorKind::Input, "no command given (sffd --help lists them)");
    if (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
        (!std::strcmp(argv[1], "help") && (argc == 2 || (argc == 3 && !std::strcmp(argv[2], "help"))))) {
      usage(stdout);
      return 0;
    }
    if (!std::strcmp(argv[1], "--version")) {
      if (argc > 2) throw Error(ErrorKind::Input, std::string("unexpected argument '") + argv[2] + "' (usage: sffd --version)");
      std::printf("sffd %s\n", sffd::version());   // the library's, as loaded
      return 0;
    }
    if (!std::strcmp(argv[1], "help")) {
      if (argc > 3) throw Error(ErrorKind::Input, "help takes one command name (sffd help deform)");
      for (const auto& c : commands())
        if (c.name == std::string(argv[2])) {
          std::fputs(cli::helpText(c).c_str(), stdout);
          return 0;
        }
      throw Error(ErrorKind::Input, std::string("unknown command '") + argv[2] + "' (sffd --help lists them)");
    }
    for (const auto& c : commands()) {
      if (c.name != std::string(argv[1])) continue;
      cli::ParsedArgs args = cli::parseArgs(c, argc - 2, argv + 2);
      if (args.has("--help")) {
        std::fputs(cli::helpText(c).c_str(), stdout);
        return 0;
      }
      checkLibraryVariables();   // what the library reads, then what the tool alone does: before any work
      cli::checkToolVariables();
      const int status = c.run(args);
      if (status == 0)
        for (const std::string& w : cli::takeWarnings()) std::fprintf(stderr, "sffd: warning: %s\n", oneLine(w.c_str()).c_str());
      return status;
    }
    throw Error(ErrorKind::Input, std::string("unknown command '") + argv[1] + "' (sffd --help lists them)");
  } catch (const Error& e) {
    std::fprintf(stderr, "sffd: error: %s\n", cli::toolLimitMessage(oneLine(e.what())).c_str());   // in the tool's words
    return e.exitStatus();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "sffd: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sffd: error: %s\n", oneLine(e.what()).c_str());
    return 1;
  }
}
