// Progress over the frames of a long run: a bar redrawn in place on a terminal, or one plain line
// every few seconds when stderr is a log file (a cluster job's output), with frames/s and the ETA.
#pragma once

#include <chrono>
#include <string>

namespace tilesplat::cli {

class FrameProgress {
 public:
  enum class Style { kQuiet, kBar, kLines };
  // `total`: the frames this run renders. `line_interval`: how often kLines prints.
  FrameProgress(std::string program, int total, Style style,
                std::chrono::duration<double> line_interval = std::chrono::seconds(10));

  // A frame is done; redraws the bar, or prints a line when the interval has passed.
  void frame_done();
  // Ends the bar's line (the summary that follows starts on its own).
  void finish();

  // "12/100 frames, 3.2 frames/s, ETA 27 s".
  std::string status() const;

 private:
  using Clock = std::chrono::steady_clock;
  std::string program_;
  int total_;
  int done_ = 0;
  Style style_;
  std::chrono::duration<double> line_interval_;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_line_ = start_;
  bool drawn_ = false;
};

// "1:02:03", "2:03" or "17 s".
std::string format_duration(double seconds);

}  // namespace tilesplat::cli
