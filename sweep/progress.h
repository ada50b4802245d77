#pragma once

#include <chrono>
#include <cstdint>
#include <ostream>

namespace linesim::sweep {

/// A one-line progress bar: done / total, failures, elapsed time and an
/// estimate of the time left, redrawn in place. Silent when `enabled` is
/// false (output not a terminal), so logs and pipes stay clean.
class ProgressBar {
 public:
  /// `already` runs were finished before (a resumed sweep): they count as
  /// done but not into the rate.
  ProgressBar(std::ostream& out, bool enabled, std::int64_t total, std::int64_t already,
              std::int64_t already_failed);
  void RunDone(bool ok);
  /// Draws again (elapsed time and ETA move on between runs).
  void Redraw();
  bool enabled() const { return enabled_; }
  /// Ends the line (once).
  void Finish();
  /// "12/40 done, 1 failed, 0:12 elapsed, ETA 0:28": what the bar shows.
  std::string Text() const;

 private:
  std::ostream& out_;
  bool enabled_;
  std::int64_t total_, already_, done_, failed_;
  std::chrono::steady_clock::time_point start_;
  bool finished_ = false;
};

/// "m:ss" or "h:mm:ss".
std::string FormatDuration(double seconds);

}  // namespace linesim::sweep
