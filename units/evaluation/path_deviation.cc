#include "units/evaluation/path_deviation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cosim/parameter_checks.h"
#include "cosim/variable_table.h"

namespace linesim::evaluation {

PathDistance DistanceToPath(const std::vector<std::array<double, 2>>& path, double x_m,
                            double y_m) {
  if (path.empty()) return {std::numeric_limits<double>::quiet_NaN(), 0.0};
  if (path.size() == 1) return {std::hypot(x_m - path[0][0], y_m - path[0][1]), 0.0};
  PathDistance best{std::numeric_limits<double>::infinity(), 0.0};
  double along_m = 0.0;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const double ax = path[i][0], ay = path[i][1];
    const double dx = path[i + 1][0] - ax, dy = path[i + 1][1] - ay;
    const double length2 = dx * dx + dy * dy;
    const double length = std::sqrt(length2);
    // Projection parameter of the point on the segment, clamped to its ends.
    const double s =
        length2 > 0.0 ? std::clamp(((x_m - ax) * dx + (y_m - ay) * dy) / length2, 0.0, 1.0) : 0.0;
    const double d = std::hypot(x_m - (ax + s * dx), y_m - (ay + s * dy));
    if (d < best.distance_m) best = {d, along_m + s * length};
    along_m += length;
  }
  return best;
}

PathDeviationUnit::PathDeviationUnit(std::string name, std::vector<std::array<double, 2>> path)
    : cosim::Unit(kTypeName, std::move(name)), path_(std::move(path)) {
  auto& v = variables();
  v.Input("pose", "m", &pose_, "true pose x, y (m), yaw (rad) in the map frame");
  v.Output("deviation", "m", &deviation_,
           "distance of the robot centre from the desired path or held point", {"pose"});
  v.Output("progress", "m", &progress_, "arc length of the nearest point along the path", {"pose"});
}

std::vector<cosim::ParameterProblem> PathDeviationUnit::CheckParameters() const {
  cosim::ParameterChecks c;
  if (path_.empty()) c.Add({"path", std::nullopt, "needs at least one point"});
  for (std::size_t i = 0; i < path_.size(); ++i) {
    if (!std::isfinite(path_[i][0]) || !std::isfinite(path_[i][1])) {
      c.Add({"path", i,
             "must be finite, got (" + cosim::FormatValue(path_[i][0]) + ", " +
                 cosim::FormatValue(path_[i][1]) + ")"});
    }
  }
  return c.Take();
}

void PathDeviationUnit::Evaluate() {
  const PathDistance d = DistanceToPath(path_, pose_[0], pose_[1]);
  deviation_ = d.distance_m;
  progress_ = d.progress_m;
}

cosim::StepResult PathDeviationUnit::DoStep(cosim::TimeNs, cosim::TimeNs) {
  return cosim::StepResult::kOk;
}

}  // namespace linesim::evaluation
