#pragma once

#include <array>
#include <string>
#include <vector>

#include "cosim/unit.h"

namespace linesim::evaluation {

/// Distance from a point to a polyline in the plane (to the point itself
/// when the polyline has one vertex), and the arc length of the nearest
/// point along it.
struct PathDistance {
  double distance_m;
  double progress_m;
};
/// `cumulative_m`: the path's models::CumulativeLengths.
PathDistance DistanceToPath(const std::vector<std::array<double, 2>>& path,
                            const std::vector<double>& cumulative_m, double x_m, double y_m);
/// For one query: computes the path's lengths first.
PathDistance DistanceToPath(const std::vector<std::array<double, 2>>& path, double x_m, double y_m);

/// Ground-truth evaluation of a robot task: how far the robot's centre is
/// from the desired path (a crossing) or from the held point (a position
/// hold). It reads the true position, never an estimate, so that the scenario's
/// metrics judge the controller and the estimators together.
class PathDeviationUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "path_deviation";

  /// `path`: one point (a hold target) or a polyline of at least two.
  PathDeviationUnit(std::string name, std::vector<std::array<double, 2>> path);

  /// The path (structural): at least one point, every point finite.
  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Initialize() override {
    ThrowIfBadParameters();
    Evaluate();
  }
  /// The deviation follows the position at each communication point; the step
  /// itself has nothing to advance.
  void UpdateOutputs() override { Evaluate(); }
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 private:
  void Evaluate();

  std::vector<std::array<double, 2>> path_;
  std::vector<double> cumulative_m_;  // path length at each point, once
  std::vector<double> position_ = std::vector<double>(2, 0.0);
  double deviation_ = 0.0;
  double progress_ = 0.0;
  double remaining_ = 0.0;
};

}  // namespace linesim::evaluation
