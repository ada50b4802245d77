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
  v.Input("position", "m", &position_, "true position x, y of base_link in the map frame");
  v.Output("deviation", "m", &deviation_,
           "distance of the robot centre from the desired path or held point", {"position"});
  v.Output("progress", "m", &progress_, "arc length of the nearest point along the path",
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
  remaining_ = cumulative_m_.empty() ? 0.0 : std::max(0.0, cumulative_m_.back() - progress_);
}

cosim::StepResult PathDeviationUnit::DoStep(cosim::TimeNs, cosim::TimeNs) {
  return cosim::StepResult::kOk;
}

}  // namespace linesim::evaluation
