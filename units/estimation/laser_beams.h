#pragma once

// What every scan matcher of this family (laser_localization,
// perfect_match_localization) does with its lasers' numbers: the same
// checks, and each beam's direction in base_link and time into its scan.

#include <cmath>
#include <cstddef>
#include <numbers>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "cosim/variable_table.h"

namespace linesim::estimation {

/// The matcher's own rules over several parameters: range_min below
/// usable_range_max, each laser's beams within one turn, scan_timeout above
/// every scan_period.
inline void AddLaserProblems(double range_min, double usable_range_max,
                             const std::vector<int>& beam_counts,
                             const std::vector<double>& angular_step,
                             const std::vector<double>& scan_period, double scan_timeout,
                             std::vector<cosim::ParameterProblem>& problems) {
  if (!(range_min < usable_range_max)) {
    problems.push_back({"usable_range_max", std::nullopt,
                        "must be > range_min (" + cosim::FormatValue(range_min) + "), got " +
                            cosim::FormatValue(usable_range_max)});
  }
  for (std::size_t k = 0; k < beam_counts.size(); ++k) {
    if (angular_step[k] * (beam_counts[k] - 1) >= 2.0 * std::numbers::pi) {
      problems.push_back({"angular_step", k,
                          "the " + std::to_string(beam_counts[k]) +
                              " beams must fit in one turn: angular_step < 2 pi / (beams - 1)"});
    }
    if (scan_period[k] >= scan_timeout) {
      problems.push_back({"scan_timeout", std::nullopt,
                          "must be > every laser's scan_period (laser " + std::to_string(k) + ": " +
                              cosim::FormatValue(scan_period[k]) + " s), got " +
                              cosim::FormatValue(scan_timeout)});
    }
  }
}

/// Beam i of a laser (mount yaw, first beam angle, angular step, scan
/// period): its direction in base_link (cos, sin) and its time into the
/// scan (the mirror turns once per scan period). Returns the middle of the
/// sweep, the time a matched pose refers to, in ns after the scan's start.
inline cosim::TimeNs LaserBeams(double mount_yaw, double first_beam_angle, double angular_step,
                                double scan_period, int beam_count, std::vector<double>& cos_out,
                                std::vector<double>& sin_out, std::vector<double>& dt_out) {
  for (int i = 0; i < beam_count; ++i) {
    const auto j = static_cast<std::size_t>(i);
    const double a = mount_yaw + first_beam_angle + i * angular_step;
    cos_out[j] = std::cos(a);
    sin_out[j] = std::sin(a);
    dt_out[j] = scan_period * i * angular_step / (2.0 * std::numbers::pi);
  }
  return cosim::SecondsToNs(0.5 * dt_out[static_cast<std::size_t>(beam_count - 1)]);
}

/// The lasers with a new scan (scan_count changed since last_count, which
/// is updated) into order[0..n), earliest match time first (scan_time +
/// mid_offset_ns: several lasers' scans are matched in time order); returns n.
inline int OrderNewScans(const std::vector<double>& scan_count, std::vector<double>& last_count,
                         const std::vector<double>& scan_time,
                         const std::vector<cosim::TimeNs>& mid_offset_ns, std::vector<int>& order) {
  int fresh = 0;
  for (std::size_t k = 0; k < scan_count.size(); ++k) {
    if (scan_count[k] == last_count[k]) continue;
    last_count[k] = scan_count[k];
    const cosim::TimeNs mk = cosim::SecondsToNs(scan_time[k]) + mid_offset_ns[k];
    int j = fresh++;
    while (j > 0) {
      const auto prev = static_cast<std::size_t>(order[static_cast<std::size_t>(j - 1)]);
      if (cosim::SecondsToNs(scan_time[prev]) + mid_offset_ns[prev] <= mk) break;
      order[static_cast<std::size_t>(j)] = order[static_cast<std::size_t>(j - 1)];
      --j;
    }
    order[static_cast<std::size_t>(j)] = static_cast<int>(k);
  }
  return fresh;
}

}  // namespace linesim::estimation
