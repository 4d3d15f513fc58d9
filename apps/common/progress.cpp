#include "progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "app_run.h"
#include "cli.h"

namespace tilesplat::cli {

FrameProgress::FrameProgress(std::string program, int total, Style style,
                             std::chrono::duration<double> line_interval)
    : FrameProgress(std::move(program), total, style, "frames", line_interval) {}

FrameProgress::FrameProgress(std::string program, int total, Style style, std::string unit,
                             std::chrono::duration<double> line_interval)
    : program_(std::move(program)),
      total_(total),
      style_(style),
      unit_(std::move(unit)),
      line_interval_(line_interval) {}

FrameProgress::Style progress_style(bool quiet) {
  if (quiet) return FrameProgress::Style::kQuiet;
  return stderr_is_terminal() ? FrameProgress::Style::kBar : FrameProgress::Style::kLines;
}

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
  std::string text = std::to_string(done_) + "/" + std::to_string(total_) + " " + unit_;
  if (!label_.empty()) text += " (" + label_ + ")";
  if (done_ > 0 && elapsed > 0) {
    const double rate = done_ / elapsed;
    text += ", " + format_fixed(rate, rate < 10 ? 2 : 1) + " " + unit_ + "/s";
    if (done_ < total_) text += ", ETA " + format_duration((total_ - done_) / rate);
  }
  return text;
}

void FrameProgress::update(int done, const std::string& label) {
  done_ = done;
  label_ = label;
  if (total_ <= 0) return;
  const auto now = Clock::now();
  if (style_ == Style::kBar) {
    // Redrawing a few times a second is enough; the last step is always shown.
    if (drawn_ && done_ < total_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    constexpr int kWidth = 30;
    const int filled = std::min(kWidth, static_cast<int>(static_cast<long long>(kWidth) * done_ / total_));
    std::string bar(static_cast<size_t>(filled), '=');
    if (filled < kWidth) bar += '>' + std::string(static_cast<size_t>(kWidth - filled - 1), ' ');
    std::fprintf(stderr, "\r[%s] %s\033[K", bar.c_str(), status().c_str());
    std::fflush(stderr);
    drawn_ = true;
  } else if (style_ == Style::kLines) {
    const int quarter = static_cast<int>(static_cast<long long>(done_) * 4 / total_);
    const bool new_quarter = quarter > last_quarter_ && total_ >= 8;  // short runs: only the end
    if (new_quarter || now - last_line_ >= line_interval_ || done_ == total_) {
      last_quarter_ = quarter;
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
