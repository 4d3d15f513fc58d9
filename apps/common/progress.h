// Progress over the steps of a long run (a render's frames, a benchmark's renders or sorts): a bar
// redrawn in place on a terminal, or a plain line now and then when stderr is a log file (a cluster
// job's output), with the rate and the time left.
#pragma once

#include <chrono>
#include <string>

namespace tilesplat::cli {

class FrameProgress {
 public:
  enum class Style { kQuiet, kBar, kLines };
  // `total`: the steps this run takes, counted in `unit` ("frames", "renders", ...). kLines prints
  // a line when `line_interval` has passed or another quarter of the run is done, and at the end.
  FrameProgress(std::string program, int total, Style style,
                std::chrono::duration<double> line_interval = std::chrono::seconds(10));
  FrameProgress(std::string program, int total, Style style, std::string unit,
                std::chrono::duration<double> line_interval = std::chrono::seconds(10));
  FrameProgress(const FrameProgress&) = delete;
  FrameProgress& operator=(const FrameProgress&) = delete;
  ~FrameProgress() { finish(); }

  // One more step is done.
  void frame_done() { update(done_ + 1); }
  // `done` steps are done, the last of them `label` (shown beside the count). Redraws the bar at most
  // ten times a second (always at the end), or prints a line.
  void update(int done, const std::string& label = "");
  // Ends the bar's line, so that what follows (the summary, an error) starts on its own.
  void finish();

  // "12/100 frames, 3.2 frames/s, ETA 27 s", with " (label)" after the count when there is one.
  std::string status() const;

 private:
  using Clock = std::chrono::steady_clock;
  std::string program_;
  int total_;
  Style style_;
  std::string unit_ = "frames";
  std::chrono::duration<double> line_interval_;
  int done_ = 0;
  std::string label_;
  int last_quarter_ = 0;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_line_ = start_;
  Clock::time_point last_draw_{};
  bool drawn_ = false;
};

// The style for stderr: quiet when asked, a bar on a terminal, lines in a log file.
FrameProgress::Style progress_style(bool quiet);

// "1:02:03", "2:03" or "17 s".
std::string format_duration(double seconds);

}  // namespace tilesplat::cli
