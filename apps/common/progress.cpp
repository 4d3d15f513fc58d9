#include "progress.h"

#include <cmath>
#include <cstdio>

#include "cli.h"

namespace tilesplat::cli {

FrameProgress::FrameProgress(std::string program, int total, Style style,
                             std::chrono::duration<double> line_interval)
    : program_(std::move(program)), total_(total), style_(style), line_interval_(line_interval) {}

std::string format_duration(double seconds) {
  const long total = std::lround(std::max(0.0, seconds));
  if (total < 60) return std::to_string(total) + " s";
  char text[32];
  if (total < 3600)
    std::snprintf(text, sizeof text, "%ld:%02ld", total / 60, total % 60);
  else
    std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", total / 3600, total / 60 % 60, total % 60);
  return text;
}

std::string FrameProgress::status() const {
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  std::string text = std::to_string(done_) + "/" + std::to_string(total_) + " frames";
  if (done_ > 0 && elapsed > 0) {
    const double rate = done_ / elapsed;
    text += ", " + format_fixed(rate, rate < 10 ? 2 : 1) + " frames/s";
    if (done_ < total_) text += ", ETA " + format_duration((total_ - done_) / rate);
  }
  return text;
}

void FrameProgress::frame_done() {
  ++done_;
  if (style_ == Style::kBar) {
    constexpr int kWidth = 30;
    const int filled = total_ > 0 ? kWidth * done_ / total_ : kWidth;
    std::string bar(static_cast<size_t>(filled), '=');
    if (filled < kWidth) bar += '>' + std::string(static_cast<size_t>(kWidth - filled - 1), ' ');
    std::fprintf(stderr, "\r[%s] %s\033[K", bar.c_str(), status().c_str());
    std::fflush(stderr);
    drawn_ = true;
  } else if (style_ == Style::kLines) {
    const auto now = Clock::now();
    if (now - last_line_ >= line_interval_ || done_ == total_) {
      last_line_ = now;
      std::fprintf(stderr, "%s: %s\n", program_.c_str(), status().c_str());
      std::fflush(stderr);
    }
  }
}

void FrameProgress::finish() {
  if (drawn_) std::fputc('\n', stderr);
  drawn_ = false;
}

}  // namespace tilesplat::cli
