#include "units/evaluation/path_deviation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cosim/variable_table.h"
#include "models/polyline.h"

namespace linesim::evaluation {

PathDistance DistanceToPath(const std::vector<std::array<double, 2>>& path,
                            const std::vector<double>& cumulative_m, double x_m, double y_m) {
  if (path.empty()) return {std::numeric_limits<double>::quiet_NaN(), 0.0};
  if (path.size() == 1) return {std::hypot(x_m - path[0][0], y_m - path[0][1]), 0.0};
  const models::PolylinePoint p =
      models::NearestOnPolyline(path, cumulative_m, x_m, y_m, models::PolylineEnds::kClamp);
  // No distance compares (a NaN position): infinitely far.
  if (!p.found) return {std::numeric_limits<double>::infinity(), 0.0};
  return {p.distance_m, p.progress_m};
}

PathDistance DistanceToPath(const std::vector<std::array<double, 2>>& path, double x_m,
                            double y_m) {
  return DistanceToPath(path, models::CumulativeLengths(path), x_m, y_m);
}

PathDeviationUnit::PathDeviationUnit(std::string name, std::vector<std::array<double, 2>> path)
    : cosim::Unit(kTypeName, std::move(name)),
      path_(std::move(path)),
      cumulative_m_(models::CumulativeLengths(path_)) {
  auto& v = variables();
  v.Parameter("band", "m", &band_,
              "the band around the path the task must stay in (paper 1 Fig. 5: 4 cm for the "
              "entire path)",
              cosim::Rule::Positive());
  v.Input("position", "m", &position_, "true position x, y of base_link in the map frame");
  v.Output("deviation", "m", &deviation_,
           "distance of the robot centre from the desired path or held point", {"position"});
  v.Output("progress", "m", &progress_, "arc length of the nearest point along the path",
           {"position"});
  v.Output("band_exceeded", "1", &band_exceeded_,
           "1 once the deviation has exceeded band at some step (latched)", {"position"});
  v.Output("success", "1", &success_,
           "1 while the deviation has stayed within band and the robot is within band of the "
           "path's end along it (a hold: within band), else 0",
           {"position"});
  v.Output("remaining", "m", &remaining_,
           "path length ahead of that nearest point (0 for a held point)", {"position"});
}

std::vector<cosim::ParameterProblem> PathDeviationUnit::CheckParameters() const {
  // The unit declares no parameters; the path is structural (given at
  // construction), so it is checked here, at its key.
  auto problems = cosim::Unit::CheckParameters();
  if (path_.empty()) problems.push_back({"path", std::nullopt, "needs at least one point"});
  for (std::size_t i = 0; i < path_.size(); ++i) {
    if (!std::isfinite(path_[i][0]) || !std::isfinite(path_[i][1])) {
      problems.push_back({"path", i,
                          "must be finite, got (" + cosim::FormatValue(path_[i][0]) + ", " +
                              cosim::FormatValue(path_[i][1]) + ")"});
    }
  }
  return problems;
}

void PathDeviationUnit::Evaluate() {
  const PathDistance d = DistanceToPath(path_, cumulative_m_, position_[0], position_[1]);
  deviation_ = d.distance_m;
  progress_ = d.progress_m;
  const bool out = exceeded_ || !(deviation_ <= band_);
  band_exceeded_ = out ? 1.0 : 0.0;
  const bool arrived = path_.size() < 2 || progress_ >= cumulative_m_.back() - band_;
  success_ = !out && arrived ? 1.0 : 0.0;
  remaining_ = cumulative_m_.empty() ? 0.0 : std::max(0.0, cumulative_m_.back() - progress_);
}

cosim::StepResult PathDeviationUnit::DoStep(cosim::TimeNs, cosim::TimeNs) {
  // The outputs of this communication point were evaluated: latch them.
  exceeded_ = band_exceeded_ != 0.0;
  return cosim::StepResult::kOk;
}

void PathDeviationUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers = {exceeded_ ? 1 : 0};
}

void PathDeviationUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.integers.size() != 1) {
    throw cosim::UnitError(Where() + ": saved state has the wrong shape");
  }
  exceeded_ = state.integers[0] != 0;
}

}  // namespace linesim::evaluation
