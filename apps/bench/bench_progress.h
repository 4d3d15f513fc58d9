// The bench's progress over a run: a bar redrawn in place on a terminal, a line per quarter otherwise.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "bench_options.h"

namespace tilesplat::bench {

// "[#####     ] 12/20 frames" redrawn in place on a terminal; occasional lines otherwise.
class Progress {
 public:
  Progress(int total, bool terminal, std::string unit = "frames")
      : total_(total), terminal_(terminal), unit_(std::move(unit)) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress() { finish(); }

  void update(int done, const std::string& label) {
    if (total_ <= 0) return;
    if (terminal_) {
      const auto now = std::chrono::steady_clock::now();
      // Redrawing a few times a second is enough; the last frame is always shown.
      if (drawn_ && done < total_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
      last_draw_ = now;
      constexpr int kBarWidth = 30;
      const int filled = static_cast<int>(static_cast<long long>(done) * kBarWidth / total_);
      std::string line = "\r[" + std::string(static_cast<size_t>(filled), '#') +
                         std::string(static_cast<size_t>(kBarWidth - filled), ' ') + "] " +
                         std::to_string(done) + "/" + std::to_string(total_) + " " + unit_ + " (" + label +
                         ")";
      const size_t visible = line.size() - 1;
      if (visible < width_) line.append(width_ - visible, ' ');
      width_ = std::max(width_, visible);
      std::fputs(line.c_str(), stderr);
      std::fflush(stderr);
      drawn_ = true;
    } else {
      // A line per quarter; short runs only say when they are done.
      const int quarter = static_cast<int>(static_cast<long long>(done) * 4 / total_);
      if (quarter <= last_quarter_ || (total_ < 8 && done < total_)) return;
      last_quarter_ = quarter;
      std::fprintf(stderr, "%s: %d/%d %s (%s)\n", kProgram, done, total_, unit_.c_str(), label.c_str());
    }
  }

  // Clears the bar so that what follows (the summary, an error) starts on a clean line.
  void finish() {
    if (!terminal_ || !drawn_) return;
    std::string blank(1, '\r');
    blank.append(width_, ' ');
    blank += '\r';
    std::fputs(blank.c_str(), stderr);
    std::fflush(stderr);
    drawn_ = false;
  }

 private:
  int total_;
  bool terminal_;
  std::string unit_;
  bool drawn_ = false;
  size_t width_ = 0;
  int last_quarter_ = 0;
  std::chrono::steady_clock::time_point last_draw_{};
};

}  // namespace tilesplat::bench
