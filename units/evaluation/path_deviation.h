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
///
/// Success as paper 1 judges it (Sec. VI-B, Fig. 5: the modified system's
/// deviation "is <4 cm for the entire path", Fig. 6: the nominal system
/// "tries to move across the moving surface, but can do so successfully
/// only with the modified system"): `success` is 1 while the deviation has
/// never exceeded `band` since the start and the robot is within `band` of
/// the path's end along it (for a hold, the first alone), else 0.
/// `band_exceeded` latches at the first step outside the band.
class PathDeviationUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "path_deviation";

  /// `path`: one point (a hold target) or a polyline of at least two.
  PathDeviationUnit(std::string name, std::vector<std::array<double, 2>> path);

  /// The path (structural): at least one point, every point finite.
  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Initialize() override {
    ThrowIfBadParameters();
    exceeded_ = false;
    Evaluate();
  }
  /// The deviation follows the position at each communication point; the
  /// step latches whether it left the band.
  void UpdateOutputs() override { Evaluate(); }
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  void Evaluate();

  std::vector<std::array<double, 2>> path_;
  std::vector<double> cumulative_m_;  // path length at each point, once
  std::vector<double> position_ = std::vector<double>(2, 0.0);
  double band_ = 0.04;  // paper 1, Fig. 5
  double deviation_ = 0.0;
  double progress_ = 0.0;
  bool exceeded_ = false;  // the deviation left the band at some step
  double band_exceeded_ = 0.0, success_ = 0.0;
  double remaining_ = 0.0;
};

}  // namespace linesim::evaluation
