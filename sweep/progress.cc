#include "sweep/progress.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace linesim::sweep {

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const auto s = static_cast<long long>(seconds + 0.5);
  char text[32];
  if (s >= 3600) {
    std::snprintf(text, sizeof text, "%lld:%02lld:%02lld", s / 3600, s / 60 % 60, s % 60);
  } else {
    std::snprintf(text, sizeof text, "%lld:%02lld", s / 60, s % 60);
  }
  return text;
}

ProgressBar::ProgressBar(std::ostream& out, bool enabled, std::int64_t total, std::int64_t already,
                         std::int64_t already_failed)
    : out_(out),
      enabled_(enabled),
      total_(total),
      already_(already),
      done_(already),
      failed_(already_failed),
      start_(std::chrono::steady_clock::now()) {
  if (enabled_) out_ << "\r" << Text() << std::flush;
}

std::string ProgressBar::Text() const {
  constexpr int kWidth = 30;
  const double fraction = total_ > 0 ? static_cast<double>(done_) / static_cast<double>(total_) : 1;
  const int filled = static_cast<int>(fraction * kWidth);
  std::string bar = "[" + std::string(static_cast<std::size_t>(filled), '#') +
                    std::string(static_cast<std::size_t>(kWidth - filled), '.') + "] ";
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const std::int64_t fresh = done_ - already_;
  const double eta =
      fresh > 0 ? elapsed / static_cast<double>(fresh) * static_cast<double>(total_ - done_) : NAN;
  return bar + std::to_string(done_) + "/" + std::to_string(total_) + " done, " +
         std::to_string(failed_) + " failed, " + FormatDuration(elapsed) + " elapsed, ETA " +
         (done_ == total_ ? "0:00" : FormatDuration(eta));
}

void ProgressBar::RunDone(bool ok) {
  ++done_;
  if (!ok) ++failed_;
  // Padding clears what a longer previous line left.
  if (enabled_) out_ << "\r" << Text() << "   " << std::flush;
}

void ProgressBar::Redraw() {
  if (enabled_ && !finished_) out_ << "\r" << Text() << "   " << std::flush;
}

void ProgressBar::Finish() {
  if (enabled_ && !finished_) out_ << "\n" << std::flush;
  finished_ = true;
}

}  // namespace linesim::sweep
