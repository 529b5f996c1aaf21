// sffd conform: each backend runs in a forked child process, so that a driver that crashes or hangs
// ends one case, not the run. The parent opens no device itself; the child reports on a pipe (one
// line an event) and writes each case's buffers to files. While a kernel compiles or the device opens, the
// child says "busy" every second, so that a driver's long compile is not taken for a hang, up to
// kCompileTimeouts times the case timeout (docs/CONFORMANCE.md "Statuses"). Test hook (docs/CONFORMANCE.md):
// SFFD_CONFORM_FAULT=crash|hang|slow-compile|stuck-compile|compile-then-hang:BACKEND[:CASE] makes that child
// crash, hang, compile for 3 case timeouts or for ever, or compile then hang at that case; slow-open:BACKEND
// makes its device's opening last 3 case timeouts.
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <optional>
#include <set>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>
#include <sffd/error.h>

#include "apps/sffd/conform.h"
#include "core/kernel_registry.h"
#include "io/io_util.h"

namespace sffd::cli::conform {

using json = nlohmann::ordered_json;

void writeCaseOutput(const fs::path& dir, const CaseOutput& out) {
  fs::create_directories(dir);
  json index = json::array();
  for (const Buffer& b : out.buffers) {
    std::ofstream f(dir / (b.name + ".f64"), std::ios::binary);
    f.write(reinterpret_cast<const char*>(b.values.data()), std::streamsize(b.values.size() * sizeof(double)));
    index.push_back({{"name", b.name}, {"unit", b.unit}, {"per_unit", b.perUnit}, {"count", b.values.size()},
                     {"file", b.name + ".f64"}});
  }
  std::ofstream(dir / "parents.u32", std::ios::binary)
      .write(reinterpret_cast<const char*>(out.parents.data()), std::streamsize(out.parents.size() * 4));
  std::ofstream(dir / "buffers.json") << json{{"format", "sffd-conform-buffers"}, {"version", 1},
                                              {"values", "little-endian float64, as the kernel wrote them"},
                                              {"buffers", index}, {"parents", "parents.u32"}}.dump(1) << "\n";
}

CaseOutput readCaseOutput(const fs::path& dir) try {
  std::ifstream in(dir / "buffers.json");
  if (!in) throw Error(ErrorKind::Input, (dir / "buffers.json").string() + ": cannot read");
  json index = json::parse(in);
  CaseOutput out;
  // A count is a claim (a --against folder may be damaged): nothing is allocated before the file holds it.
  auto sizeOf = [](const fs::path& p, size_t count, size_t unit) {
    std::error_code ec;
    const uintmax_t bytes = fs::file_size(p, ec);
    if (ec || bytes / unit < count) throw Error(ErrorKind::Input, p.string() + ": shorter than its buffers.json says");
    return count;
  };
  auto readRaw = [](const fs::path& p, void* data, size_t bytes) {
    std::ifstream f(p, std::ios::binary);
    if (!f.read(static_cast<char*>(data), std::streamsize(bytes)) && bytes)
      throw Error(ErrorKind::Input, p.string() + ": shorter than its buffers.json says");
  };
  for (const json& b : index.at("buffers")) {
    const fs::path file = dir / b.at("file").get<std::string>();
    Buffer buf{b.at("name"), b.at("unit"), b.at("per_unit"), std::vector<double>(sizeOf(file, b.at("count").get<size_t>(), 8))};
    readRaw(file, buf.values.data(), buf.values.size() * 8);
    out.buffers.push_back(std::move(buf));
  }
  std::error_code ec;
  const uintmax_t parentBytes = fs::file_size(dir / "parents.u32", ec);
  if (ec) throw Error(ErrorKind::Input, (dir / "parents.u32").string() + ": cannot read: " + ec.message());
  out.parents.resize(parentBytes / 4);
  readRaw(dir / "parents.u32", out.parents.data(), out.parents.size() * 4);
  return out;
} catch (const json::exception& e) {   // a damaged or foreign index
  throw Error(ErrorKind::Input, (dir / "buffers.json").string() + ": not a --dump buffer index: " + io::oneLine(e.what()));
}

namespace {

// A kernel compile counts as progress for at most this many case timeouts (10 min by default).
constexpr double kCompileTimeouts = 10;

// The child's lines come from its main thread and its heartbeat: one write each, one at a time.
std::mutex gSayMutex;

void say(int fd, const std::string& line) {
  std::lock_guard<std::mutex> lock(gSayMutex);
  std::string l = line;
  for (char& c : l)
    if (c == '\n') c = ' ';
  l += '\n';
  for (size_t at = 0; at < l.size();) {
    ssize_t n = ::write(fd, l.data() + at, l.size() - at);
    if (n <= 0) return;
    at += size_t(n);
  }
}

// The test hook's value, KIND:BACKEND[:CASE], in its parts (CASE empty when absent).
struct Fault {
  std::string kind, backend, caseName;
  bool hasCase = false;
};
Fault faultOf(const std::string& s) {
  Fault f;
  const size_t a = s.find(':'), b = a == std::string::npos ? a : s.find(':', a + 1);
  f.kind = s.substr(0, a);
  if (a != std::string::npos) f.backend = s.substr(a + 1, b == std::string::npos ? b : b - a - 1);
  if (b != std::string::npos) f.caseName = s.substr(b + 1), f.hasCase = true;
  return f;
}

}  // namespace

void checkConformFaultVariable() {
  const char* v = std::getenv("SFFD_CONFORM_FAULT");
  if (!v || !*v) return;
  static const std::set<std::string> kinds{"crash", "hang", "slow-compile", "stuck-compile", "compile-then-hang", "slow-open"};
  const Fault f = faultOf(v);
  // A value that named no fault, or one that could never happen (slow-open of a case), injected none.
  if (kinds.count(f.kind) && std::find(std::begin(kBackendNames), std::end(kBackendNames), f.backend) != std::end(kBackendNames) && (!f.hasCase || (!f.caseName.empty() && f.kind != "slow-open"))) return;
  throw Error(ErrorKind::Input, std::string("SFFD_CONFORM_FAULT must be KIND:BACKEND[:CASE] (KIND crash, hang, slow-compile, "
                                            "stuck-compile or compile-then-hang) or slow-open:BACKEND, not '") + v + "'");
}

namespace {

// The test hook: "crash:vulkan", "hang:gl-egl:CASE", "slow-compile:cpu:CASE" (a compile of 3 case
// timeouts, which is progress), "stuck-compile:cpu" (one that never ends) or "compile-then-hang:cpu" (a
// slow compile, then a hang: no progress once the compile has ended), at the start of a case; "slow-open:cpu"
// (an opening of 3 case timeouts, progress too) while the device opens (caseName empty). checkConformFaultVariable
// has refused any other value.
void injectFault(const std::string& backend, const std::string& caseName, double timeoutSeconds) {
  const char* v = std::getenv("SFFD_CONFORM_FAULT");
  if (!v) return;
  const Fault f = faultOf(v);
  const std::string& kind = f.kind;
  if (f.backend != backend || (f.hasCase && f.caseName != caseName) || (kind == "slow-open") != caseName.empty()) return;
  if (kind == "slow-open") std::this_thread::sleep_for(std::chrono::duration<double>(3 * timeoutSeconds));
  if (kind == "crash") ::raise(SIGSEGV);
  if (kind == "hang")
    for (;;) ::pause();
  if (kind == "slow-compile" || kind == "stuck-compile" || kind == "compile-then-hang") {
    {
      CompileScope compiling(backend, "injected", {});
      if (kind == "stuck-compile")
        for (;;) ::pause();
      std::this_thread::sleep_for(std::chrono::duration<double>(3 * timeoutSeconds));
    }
    if (kind == "compile-then-hang")
      for (;;) ::pause();
  }
}

// Says "busy" every second (or every fifth of the case timeout, if shorter) while a kernel compile is in
// flight, or the device is being opened, for less than kCompileTimeouts case timeouts: a driver compiling
// or starting is making progress (lavapipe's opening took seconds after runs that wrote gigabytes, and a
// GPU driver's first opening can take seconds too). "idle" once neither is, so that a later hang is not
// taken for a compile.
class Heartbeat {
 public:
  Heartbeat(int fd, double timeoutSeconds)
      : thread_([this, fd, timeoutSeconds] {
          const auto period = std::chrono::duration<double>(std::min(1.0, timeoutSeconds / 5));
          bool busy = false;
          std::unique_lock<std::mutex> lock(mutex_);
          while (!cv_.wait_for(lock, period, [this] { return stop_; })) {
            double compiling = oldestCompileInFlightSeconds();
            if (openingSince_)
              compiling = std::max(compiling, std::chrono::duration<double>(Clock::now() - *openingSince_).count());
            if (compiling >= 0 && compiling < kCompileTimeouts * timeoutSeconds) {
              say(fd, "busy");
              busy = true;
            } else if (busy && compiling < 0) {
              say(fd, "idle");
              busy = false;
            }
          }
        }) {}
  ~Heartbeat() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_one();
    thread_.join();
  }
  // Brackets the device's opening.
  void opening(bool on) {
    std::lock_guard<std::mutex> lock(mutex_);
    openingSince_ = on ? std::optional<Clock::time_point>(Clock::now()) : std::nullopt;
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::optional<Clock::time_point> openingSince_;
  std::thread thread_;   // last: starts once the members it reads exist
};

// The child: opens the device, then runs cases[first..] and reports each on `fd`.
void childMain(const std::string& name, const std::vector<Case>& cases, size_t first, const fs::path& dir,
               const RunnerOptions& options, int fd) {
  Heartbeat heartbeat(fd, options.timeoutSeconds);
  std::optional<Device> device;
  try {
    DeviceRequest req;
    req.name = name;
    req.deviceSubstring = options.deviceSubstring;
    heartbeat.opening(true);
    injectFault(name, "", options.timeoutSeconds);
    device.emplace(Device::open(req));
    heartbeat.opening(false);
  } catch (const std::exception& e) {
    heartbeat.opening(false);
    say(fd, std::string("skip-backend ") + e.what());
    return;
  }
  say(fd, "open " + deviceJson(device->label(), device->info()));
  for (size_t i = first; i < cases.size(); ++i) {
    say(fd, "start " + std::to_string(i));
    injectFault(name, cases[i].name, options.timeoutSeconds);
    try {
      writeCaseOutput(dir / cases[i].name, runCase(*device, cases[i]));
      say(fd, "done " + std::to_string(i));
    } catch (const Error& e) {
      say(fd, (e.kind() == ErrorKind::Device ? "skip " : "fail ") + std::to_string(i) + " " + e.what());
    } catch (const std::exception& e) {
      say(fd, "fail " + std::to_string(i) + " " + e.what());
    }
  }
}

DeviceInfo infoFromJson(const json& j) {
  auto str = [&](const char* k) { return j.contains(k) && j[k].is_string() ? j[k].get<std::string>() : std::string(); };
  auto num = [&](const char* k) { return j.contains(k) && j[k].is_number() ? j[k].get<uint32_t>() : 0u; };
  DeviceInfo d;
  d.api = str("api"), d.provider = str("provider"), d.name = str("device"), d.driver = str("driver"), d.type = str("type");
  d.driverVersion = str("driver_version"), d.uuid = str("uuid"), d.shaderCache = str("shader_cache");
  d.vendorId = num("vendor_id"), d.deviceId = num("device_id");
  d.limits.float64 = j.value("float64", false);
  return d;
}

std::string signalText(int status) {
  if (WIFSIGNALED(status)) return "killed by signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
  return "exited with status " + std::to_string(WEXITSTATUS(status)) + " before finishing";
}

}  // namespace

BackendRun runBackend(const std::string& name, const std::vector<Case>& cases, const fs::path& dir,
                      const RunnerOptions& options) {
  using Clock = std::chrono::steady_clock;
  BackendRun run;
  run.name = run.label = name;
  run.dir = dir;
  run.cases.assign(cases.size(), CaseRun{Status::Skip, "not run"});
  size_t next = 0;
  while (next < cases.size()) {
    int fds[2];
    if (::pipe(fds) != 0) throw Error(ErrorKind::Internal, "conform: cannot create a pipe");
    std::fflush(stdout);
    std::fflush(stderr);
    const pid_t pid = ::fork();
    if (pid < 0) throw Error(ErrorKind::Internal, "conform: cannot fork");
    if (pid == 0) {
      ::close(fds[0]);
      childMain(name, cases, next, dir, options, fds[1]);
      std::fflush(nullptr);
      ::_exit(0);
    }
    ::close(fds[1]);
    long current = -1;   // the case the child is in
    bool timedOut = false, backendSkipped = false, compiling = false;   // compiling: the last line was "busy"
    auto deadline = Clock::now() + std::chrono::duration<double>(options.timeoutSeconds);
    std::string pending;
    for (;;) {
      // In double: a huge --timeout (1e300 s) has no integer count of milliseconds; poll waits a day at most at once.
      const double left = std::chrono::duration<double, std::milli>(deadline - Clock::now()).count();
      pollfd p{fds[0], POLLIN, 0};
      if (left <= 0) {
        ::kill(pid, SIGKILL);
        timedOut = true;
        break;
      }
      if (::poll(&p, 1, int(std::ceil(std::min(left, 86400e3)))) == 0) continue;   // the deadline is checked above
      char buf[4096];
      const ssize_t n = ::read(fds[0], buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      pending.append(buf, size_t(n));
      for (size_t eol; (eol = pending.find('\n')) != std::string::npos; pending.erase(0, eol + 1)) {
        const std::string line = pending.substr(0, eol), word = line.substr(0, line.find(' '));
        const std::string rest = line.find(' ') == std::string::npos ? "" : line.substr(line.find(' ') + 1);
        deadline = Clock::now() + std::chrono::duration<double>(options.timeoutSeconds);
        compiling = word == "busy";
        if (word == "busy" || word == "idle") {
        } else if (word == "open") {
          json j = json::parse(rest);
          run.opened = true;
          run.label = j.value("backend", name);
          run.info = infoFromJson(j);
        } else if (word == "skip-backend") {
          run.skipReason = rest;
          backendSkipped = true;
        } else if (word == "start") {
          current = std::stol(rest);
        } else {
          // done|skip|fail I [why]
          const size_t i = std::stoul(rest.substr(0, rest.find(' ')));
          const std::string why = rest.find(' ') == std::string::npos ? "" : rest.substr(rest.find(' ') + 1);
          run.cases[i] = {word == "done" ? Status::Pass : word == "skip" ? Status::Skip : Status::Fail, why};
          current = -1;
          next = i + 1;
        }
      }
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    ::close(fds[0]);
    if (backendSkipped) {
      for (CaseRun& c : run.cases) c = {Status::Skip, run.skipReason};
      break;
    }
    const bool clean = !timedOut && WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (clean && next >= cases.size()) break;
    const Status s = timedOut ? Status::Timeout : Status::Crash;
    char t[128];
    if (compiling)
      std::snprintf(t, sizeof t, "%s ran past %g s (%g times --timeout)", run.opened ? "a kernel compile" : "opening the device",
                    kCompileTimeouts * options.timeoutSeconds, kCompileTimeouts);
    else
      std::snprintf(t, sizeof t, "no progress for %g s", options.timeoutSeconds);
    const std::string why = timedOut ? std::string(t) : signalText(status);
    if (current < 0) {   // died opening the device or between cases: nothing more can be trusted
      const std::string where = run.opened || (timedOut && compiling) ? "" : " while opening the device";
      for (size_t i = next; i < cases.size(); ++i) run.cases[i] = {s, why + where};
      break;
    }
    run.cases[size_t(current)] = {s, why};
    next = size_t(current) + 1;
  }
  return run;
}

}  // namespace sffd::cli::conform
