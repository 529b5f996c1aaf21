// What the end-to-end tests share: running the sffd binary, fresh temporary folders, reading files,
// and small meshes written by the test itself (so a test needs no data file).
#pragma once
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "backends/backend_test_support.h"

namespace sffd::test {

namespace fs = std::filesystem;

struct RunResult {
  int status = -1;   // exit status; 128 when the process did not exit normally (a crash)
  std::string out, err;
  long maxRssKiB = 0;   // the peak RSS of the largest process of the run (sffd's)
};

inline std::string slurp(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// A new empty folder under the system's temporary folder, unique to this process and name.
inline fs::path tempDir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("sffd_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// How long one run may take before it is killed (status 124): past a cold shader cache's compile and
// the device timeout (60 s), so that a hung driver fails its test instead of waiting forever.
constexpr int kRunTimeoutSeconds = 600;

// The shell command line `command` ("VAR=value ... PROGRAM ARGS") bounded by kRunTimeoutSeconds.
inline std::string bounded(const std::string& command) {
  return "timeout -k 10 " + std::to_string(kRunTimeoutSeconds) + " env " + command;
}

// Runs the sffd binary (SFFD_BINARY) with arguments shell-quoted by the caller, after an optional
// environment prefix ("VAR=value ...", or a command that runs the rest, such as "env -u DISPLAY").
inline RunResult runSffd(const std::string& args, const std::string& env = "") {
  static int serial = 0;
  fs::path dir = tempDir("run" + std::to_string(serial++));
  const std::string outFile = (dir / "stdout").string(), errFile = (dir / "stderr").string();
  const std::string cmd = bounded(env + " " + SFFD_BINARY + " " + args) + " >" + outFile + " 2>" + errFile;
  RunResult r;
  // std::system, with wait4's usage: its peak RSS is the largest of the shell's and what it waited for.
  int raw = -1;
  if (const pid_t pid = ::fork(); pid == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  } else if (pid > 0) {
    struct rusage usage {};
    while (::wait4(pid, &raw, 0, &usage) < 0 && errno == EINTR) {
    }
    r.maxRssKiB = usage.ru_maxrss;
  }
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
  r.out = slurp(outFile);
  r.err = slurp(errFile);
  if (r.status == 124) r.err += "runSffd: killed after " + std::to_string(kRunTimeoutSeconds) + " s: " + args + "\n";
  fs::remove_all(dir);
  return r;
}

// The line `sffd devices` gives a backend of that name here (asked once a process), or "" when it lists none.
inline std::string deviceLine(const std::string& backend) {
  static const std::string listed = "\n" + runSffd("devices").out;
  size_t at = listed.find("\n" + backend + " ");
  return at == std::string::npos ? std::string() : listed.substr(at + 1, listed.find('\n', at + 1) - at - 1);
}

inline bool hasDevice(const std::string& backend) { return !deviceLine(backend).empty(); }

// Whether that backend runs double-precision kernels here ("[f64]" on its line).
inline bool hasDoubles(const std::string& backend) { return deviceLine(backend).find("[f64]") != std::string::npos; }

// Whether a test may run on backend `name`: this machine has it, or must have it (then its absence fails).
inline bool usable(const std::string& backend) { return hasDevice(backend) || sffd::testing::requiredHere(backend); }

// An axis-aligned box as OBJ with one normal per face: 8 positions, 12 triangles, every edge a crease.
inline void writeBoxObj(const fs::path& path, double cx, double cy, double cz, double half) {
  std::ofstream f(path);
  for (int i = 0; i < 8; ++i)
    f << "v " << cx + ((i & 1) ? half : -half) << ' ' << cy + ((i & 2) ? half : -half) << ' '
      << cz + ((i & 4) ? half : -half) << '\n';
  f << "vn -1 0 0\nvn 1 0 0\nvn 0 -1 0\nvn 0 1 0\nvn 0 0 -1\nvn 0 0 1\n";
  // Per face: four corners counter-clockwise seen from outside (1-based), and its normal.
  const int faces[6][5] = {{1, 5, 7, 3, 1}, {2, 4, 8, 6, 2}, {1, 2, 6, 5, 3},
                           {3, 7, 8, 4, 4}, {1, 3, 4, 2, 5}, {5, 6, 8, 7, 6}};
  for (const auto& q : faces) {
    f << "f " << q[0] << "//" << q[4] << ' ' << q[1] << "//" << q[4] << ' ' << q[2] << "//" << q[4] << '\n';
    f << "f " << q[0] << "//" << q[4] << ' ' << q[2] << "//" << q[4] << ' ' << q[3] << "//" << q[4] << '\n';
  }
}

}  // namespace sffd::test
