#include "apps/sffd/progress_line.h"

#include <unistd.h>

#include <cstdio>

namespace sffd::cli {

bool progressWanted(const ParsedArgs& args) { return !args.has("--quiet") && ::isatty(STDERR_FILENO); }

ProgressCallback ProgressLine::callback() {
  if (!enabled_) return {};
  return [this](const Progress& p) {
    report(p);
    return true;
  };
}

void ProgressLine::report(const Progress& p) {
  using namespace std::chrono;
  const auto now = steady_clock::now();
  if (!running_) running_ = true, start_ = now;
  // Short work shows nothing; long work is redrawn at most ten times a second.
  if (now - start_ < seconds(1) || (shown_ && now - drawn_ < milliseconds(100))) return;
  char text[96];
  std::snprintf(text, sizeof text, "sffd: %-9s %3d%%", p.stage, int(p.fraction * 100 + 0.5));
  if (shown_ && last_ == text) return;
  std::fprintf(stderr, "\r%s", text);
  std::fflush(stderr);
  shown_ = true;
  drawn_ = now;
  last_ = text;
}

void ProgressLine::clear() {
  if (shown_) {
    std::fprintf(stderr, "\r%*s\r", int(last_.size()), "");
    std::fflush(stderr);
  }
  running_ = shown_ = false;
  last_.clear();
}

}  // namespace sffd::cli
