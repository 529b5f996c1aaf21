// The command-line tool's progress indicator: one line on stderr, "sffd: deform  42%", redrawn in
// place and erased when the work is done. Shown only for work that has run about a second, when
// stderr is a terminal and --quiet is not given; nothing is written otherwise.
#pragma once
#include <chrono>
#include <string>

#include <sffd/deformer.h>

#include "apps/sffd/cli.h"

namespace sffd::cli {

// Whether the options and stderr allow a progress line.
bool progressWanted(const ParsedArgs& args);

class ProgressLine {
 public:
  explicit ProgressLine(bool enabled) : enabled_(enabled) {}
  ~ProgressLine() { clear(); }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  // A callback for DeformOptions::progress that draws on this line (empty when disabled); the line
  // must outlive its use. It never cancels.
  ProgressCallback callback();
  // Erases the line if it is shown; the next report starts a new second of grace.
  void clear();

 private:
  void report(const Progress& p);
  bool enabled_;
  bool running_ = false, shown_ = false;
  std::chrono::steady_clock::time_point start_, drawn_;
  std::string last_;
};

}  // namespace sffd::cli
