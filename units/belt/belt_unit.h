#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/scene.h"

namespace linesim::belt {

/// The assembly lines of a scenario: `belt_count` belts, each a rectangle of
/// moving floor with its own exogenous on/off schedule (paper 1, Sec. II:
/// factories give no reliable on/off signal, and a running line moves at an
/// almost constant speed, +-10 %).
///
/// While a belt is scheduled on, its target speed is
///   nominal_speed * (1 + speed_variation * f(t)),
///   f(t) = (1/K) sum_k sin(2 pi t / (variation_period * r_k) + phi_k),  K = 3,
/// a smooth signal bounded to [-1, 1]. The period factors r_k (0.6, 1.0 and
/// 1.4, each times a jitter uniform in [0.9, 1.1]) and phases phi_k (uniform
/// in [0, 2 pi)) are drawn once per belt, belt after belt, from a
/// std::mt19937_64 seeded with the constructor's seed.
/// While off, the target is 0. The actual speed follows the target with a
/// slew limit of `acceleration`, so a start or stop takes nominal_speed /
/// acceleration seconds; a step is split at the switching times inside it,
/// so the ramps do not depend on the step size.
///
/// At the start time a belt that is scheduled on already runs at its target
/// speed (the line was running before the scenario began).
class BeltUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "belt";
  /// Sinusoids in the speed variation signal f(t).
  static constexpr int kVariationTerms = 3;

  /// One change of a belt's scheduled state.
  struct Switch {
    cosim::TimeNs time;
    bool on;
  };

  /// `schedules` holds one list of switches per belt in increasing time order
  /// (CheckParameters reports any that is not), or is empty for no switches
  /// at all. Throws cosim::UnitError if belt_count < 1 or `schedules` has
  /// another size.
  BeltUnit(std::string name, int belt_count, std::vector<std::vector<Switch>> schedules,
           std::uint64_t seed);
  /// The belts of a scene: one per scene belt, its parameters starting at
  /// the scene's values (still settable as parameters) and its schedule the
  /// scene's. Throws cosim::UnitError if `belts` is empty.
  BeltUnit(std::string name, const std::vector<models::Belt>& belts, std::uint64_t seed);

  /// The declared rules (with the belt index), an initially_on between 0
  /// and 1, and a schedule whose times do not increase, reported as variable
  /// "schedules.<belt>" with the index of the offending switch.
  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  /// Validates the parameters (throws cosim::UnitError listing every
  /// problem) and sets each belt to its state at the start time.
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  int belt_count() const { return belt_count_; }
  /// f(t) of belt `b`, in [-1, 1]; depends on the seed and variation_period.
  double VariationSignal(int b, cosim::TimeNs t) const;
  /// The scheduled state of belt `b` at time `t`: the last switch at or
  /// before t, else initially_on.
  bool ScheduledOn(int b, cosim::TimeNs t) const;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  /// Speed the belt tends to at time t in the given scheduled state.
  double TargetSpeed(std::size_t b, bool on, cosim::TimeNs t) const;
  void ComputeOutputs(cosim::TimeNs t);
  /// The unit vectors of direction_, once per parameter set instead of per
  /// step.
  void CacheDirections();

  int belt_count_;
  std::vector<std::vector<Switch>> schedules_;
  // Per belt, kVariationTerms each: period factors r_k and phases phi_k.
  std::vector<double> period_factors_, phases_rad_;

  // Parameters, one element per belt.
  std::vector<double> direction_, nominal_speed_, initially_on_, speed_variation_,
      variation_period_, acceleration_;

  // cos and sin of direction_ (CacheDirections).
  std::vector<double> direction_x_, direction_y_;

  // Outputs.
  std::vector<double> velocity_, belt_speed_, on_, travel_;

  cosim::TimeNs start_ = 0;
};

}  // namespace linesim::belt
