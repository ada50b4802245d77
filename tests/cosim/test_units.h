#pragma once

// Units used only by the cosim tests. Each is as small as the test that uses
// it allows; none includes robot code.

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>
#include <utility>
#include <vector>

#include "cosim/unit.h"

namespace linesim::cosim::test_units {

/// Exact solution of x' = A x + b over dt with b held constant (zero-order
/// hold): the top rows of exp([[A, b], [0, 0]] dt) applied to [x; 1].
template <int N>
Eigen::Matrix<double, N, 1> ExactZohStep(const Eigen::Matrix<double, N, N>& a,
                                         const Eigen::Matrix<double, N, 1>& b,
                                         const Eigen::Matrix<double, N, 1>& x, double dt_s) {
  Eigen::Matrix<double, N + 1, N + 1> m = Eigen::Matrix<double, N + 1, N + 1>::Zero();
  m.template topLeftCorner<N, N>() = a * dt_s;
  m.template topRightCorner<N, 1>() = b * dt_s;
  const Eigen::Matrix<double, N + 1, N + 1> e = m.exp();
  return e.template topLeftCorner<N, N>() * x + e.template topRightCorner<N, 1>();
}

/// The two-mass-spring-damper: wall -k1,d1- m1 -k2,d2- m2.
struct TwoMassParams {
  double m1_kg = 1.0;
  double k1_n_per_m = 10.0;
  double d1_ns_per_m = 1.0;
  double m2_kg = 1.0;
  double k2_n_per_m = 100.0;
  double d2_ns_per_m = 1.0;
  double x1_0_m = 0.1;
  double v1_0_mps = 0.0;
  double x2_0_m = 0.0;
  double v2_0_mps = 0.0;
};

/// Mass 1 on the wall spring and damper, driven by the coupling force. Its
/// state lives outside the variable table (so that SaveInternal matters);
/// the outputs are copies of it.
class Mass1Unit : public Unit {
 public:
  explicit Mass1Unit(const TwoMassParams& p, std::string name = "mass1")
      : Unit("Mass1", std::move(name)), p_(p) {
    auto& t = variables();
    t.Parameter("m1", "kg", &p_.m1_kg, "mass 1");
    t.Parameter("k1", "N/m", &p_.k1_n_per_m, "wall spring");
    t.Parameter("d1", "N.s/m", &p_.d1_ns_per_m, "wall damper");
    t.Parameter("x0", "m", &p_.x1_0_m, "initial position");
    t.Parameter("v0", "m/s", &p_.v1_0_mps, "initial velocity");
    t.Input("force", "N", &force_n_, "coupling force on mass 1");
    t.Output("x", "m", &x_m_, "position of mass 1", {});
    t.Output("v", "m/s", &v_mps_, "velocity of mass 1", {});
  }

  void Initialize() override {
    state_ << p_.x1_0_m, p_.v1_0_mps;
    Publish();
  }

  StepResult DoStep(TimeNs, TimeNs dt) override {
    Eigen::Matrix2d a;
    a << 0.0, 1.0, -p_.k1_n_per_m / p_.m1_kg, -p_.d1_ns_per_m / p_.m1_kg;
    const Eigen::Vector2d b(0.0, force_n_ / p_.m1_kg);
    state_ = ExactZohStep<2>(a, b, state_, NsToSeconds(dt));
    Publish();
    return StepResult::kOk;
  }

 protected:
  void SaveInternal(UnitState& s) const override {
    s.reals.push_back(state_[0]);
    s.reals.push_back(state_[1]);
  }
  void RestoreInternal(const UnitState& s) override {
    if (s.reals.size() != 2) {
      throw std::invalid_argument("Mass1 state needs 2 reals, got " +
                                  std::to_string(s.reals.size()));
    }
    state_ << s.reals[0], s.reals[1];
  }

 private:
  void Publish() {
    x_m_ = state_[0];
    v_mps_ = state_[1];
  }

  TwoMassParams p_;
  Eigen::Vector2d state_ = Eigen::Vector2d::Zero();
  double force_n_ = 0.0;
  double x_m_ = 0.0;
  double v_mps_ = 0.0;
};

/// Mass 2 and the spring/damper that tie it to mass 1. Output: the force
/// on mass 1, which depends directly on the inputs x1, v1.
class CouplingUnit : public Unit {
 public:
  explicit CouplingUnit(const TwoMassParams& p, std::string name = "coupling")
      : Unit("Coupling", std::move(name)), p_(p) {
    auto& t = variables();
    t.Parameter("m2", "kg", &p_.m2_kg, "mass 2");
    t.Parameter("k2", "N/m", &p_.k2_n_per_m, "coupling spring");
    t.Parameter("d2", "N.s/m", &p_.d2_ns_per_m, "coupling damper");
    t.Input("x1", "m", &x1_m_, "position of mass 1");
    t.Input("v1", "m/s", &v1_mps_, "velocity of mass 1");
    t.Output("force", "N", &force_n_, "force of the coupling on mass 1", {"x1", "v1"});
    t.Local("x2", "m", &x2_m_, "position of mass 2");
    t.Local("v2", "m/s", &v2_mps_, "velocity of mass 2");
  }

  void Initialize() override {
    x2_m_ = p_.x2_0_m;
    v2_mps_ = p_.v2_0_mps;
    Publish();
  }
  /// With `update_outputs`, the force follows new inputs at a
  /// communication point (FMI get-after-set); without, it is computed in
  /// DoStep only, as in the classic formulation of this benchmark.
  void UpdateOutputs() override {
    if (update_outputs_) Publish();
  }
  bool update_outputs_ = false;

  StepResult DoStep(TimeNs, TimeNs dt) override {
    const double k = p_.k2_n_per_m / p_.m2_kg;
    const double d = p_.d2_ns_per_m / p_.m2_kg;
    Eigen::Matrix2d a;
    a << 0.0, 1.0, -k, -d;
    const Eigen::Vector2d b(0.0, k * x1_m_ + d * v1_mps_);
    const Eigen::Vector2d x =
        ExactZohStep<2>(a, b, Eigen::Vector2d(x2_m_, v2_mps_), NsToSeconds(dt));
    x2_m_ = x[0];
    v2_mps_ = x[1];
    Publish();
    return StepResult::kOk;
  }

 private:
  void Publish() {
    force_n_ = p_.k2_n_per_m * (x2_m_ - x1_m_) + p_.d2_ns_per_m * (v2_mps_ - v1_mps_);
  }

  TwoMassParams p_;
  double x1_m_ = 0.0;
  double v1_mps_ = 0.0;
  double force_n_ = 0.0;
  double x2_m_ = 0.0;
  double v2_mps_ = 0.0;
};

struct StepCall {
  TimeNs t;
  TimeNs dt;
};

/// Output "value" = offset + slope * t (t in s); records its DoStep calls.
class RampSource : public Unit {
 public:
  explicit RampSource(std::string name, double slope = 1.0, double offset = 0.0,
                      std::string unit = "s")
      : Unit("Ramp", std::move(name)), slope_(slope), offset_(offset) {
    variables().Parameter("slope", unit + "/s", &slope_, "rate of change");
    variables().Parameter("offset", unit, &offset_, "value at t = 0");
    variables().Output("value", unit, &value_, "offset + slope t", {});
  }
  void Setup(TimeNs start, TimeNs) override { start_ = start; }
  void Initialize() override { value_ = Evaluate(start_); }
  StepResult DoStep(TimeNs t, TimeNs dt) override {
    calls.push_back({t, dt});
    value_ = Evaluate(t + dt);
    return StepResult::kOk;
  }
  std::vector<StepCall> calls;

 private:
  double Evaluate(TimeNs t) const { return offset_ + slope_ * NsToSeconds(t); }
  double slope_;
  double offset_;
  double value_ = 0.0;
  TimeNs start_ = 0;
};

/// Records, at each DoStep, the time, the step and the input it sees.
class RecordingSink : public Unit {
 public:
  explicit RecordingSink(std::string name, std::string unit = "s") : Unit("Sink", std::move(name)) {
    variables().Input("value", std::move(unit), &value_, "recorded input");
  }
  StepResult DoStep(TimeNs t, TimeNs dt) override {
    calls.push_back({t, dt});
    seen.push_back(value_);
    return StepResult::kOk;
  }
  std::vector<StepCall> calls;
  std::vector<double> seen;

 private:
  double value_ = 0.0;
};

/// y = u, with or without declared direct feedthrough. Without it the
/// output is the input of the previous step (a one-step delay).
class PassThrough : public Unit {
 public:
  PassThrough(std::string name, bool feedthrough, std::string unit = "1")
      : Unit("PassThrough", std::move(name)), feedthrough_(feedthrough) {
    variables().Input("u", unit, &u_, "input");
    variables().Output("y", unit, &y_, "copy of u",
                       feedthrough ? std::vector<std::string>{"u"} : std::vector<std::string>{});
  }
  void Initialize() override {
    if (feedthrough_) y_ = u_;
  }
  void UpdateOutputs() override {
    if (feedthrough_) y_ = u_;
  }
  StepResult DoStep(TimeNs, TimeNs) override {
    y_ = u_;
    return StepResult::kOk;
  }

 private:
  bool feedthrough_;
  double u_ = 0.0;
  double y_ = 0.0;
};

/// y = u with feedthrough; Initialize refuses an input above `limit`, as a
/// unit checking a value it receives from another unit would.
class PickyUnit : public Unit {
 public:
  PickyUnit(std::string name, double limit) : Unit("Picky", std::move(name)), limit_(limit) {
    variables().Input("u", "1", &u_, "checked input");
    variables().Output("y", "1", &y_, "copy of u", {"u"});
  }
  void Initialize() override {
    if (u_ > limit_) throw UnitError("input u = " + std::to_string(u_) + " above its limit");
    y_ = u_;
  }
  StepResult DoStep(TimeNs, TimeNs) override {
    y_ = u_;
    return StepResult::kOk;
  }

 private:
  double limit_;
  double u_ = 0.0;
  double y_ = 0.0;
};

/// Every kind of port, for the connection checks and the recorder.
class PortsUnit : public Unit {
 public:
  explicit PortsUnit(std::string name) : Unit("Ports", std::move(name)) {
    auto& t = variables();
    t.Parameter("gain", "1", &gain_, "a parameter");
    t.Input("pos", "m", &pos_, "a position");
    t.Input("speed", "m/s", &speed_, "a speed");
    t.Input("flag", &flag_, "a flag");
    t.Input("count", &count_, "a count");
    t.Input("scan", "m", &scan_, "three ranges");
    t.Input("label", &label_, "a string input");
    t.Output("pos_out", "m", &pos_out_, "a position", {});
    t.Output("speed_out", "m/s", &speed_out_, "a speed", {});
    t.Output("ratio_out", "1", &ratio_out_, "a dimensionless real", {});
    t.Output("flag_out", &flag_out_, "a flag", {});
    t.Output("count_out", &count_out_, "a count", {});
    t.Output("scan_out", "m", &scan_out_, "three ranges", {});
    t.Output("scan4_out", "m", &scan4_out_, "four ranges", {});
    t.Local("internal", "m", &internal_, "a local");
  }
  StepResult DoStep(TimeNs, TimeNs) override { return StepResult::kOk; }

 private:
  double gain_ = 1.0;
  double pos_ = 0.0;
  double speed_ = 0.0;
  bool flag_ = false;
  std::int64_t count_ = 0;
  std::vector<double> scan_ = {0.0, 0.0, 0.0};
  std::string label_;
  double pos_out_ = 1.5;
  double speed_out_ = -2.0;
  double ratio_out_ = 0.25;
  bool flag_out_ = true;
  std::int64_t count_out_ = 7;
  std::vector<double> scan_out_ = {1.0, 2.0, 3.0};
  std::vector<double> scan4_out_ = {4.0, 5.0, 6.0, 7.0};
  double internal_ = 0.0;
};

/// Output y = t (s) until `fail_time`, where it misbehaves in the chosen way.
class FaultyUnit : public Unit {
 public:
  enum class Mode { kNaN, kInf, kError, kDiscard, kThrow };
  FaultyUnit(std::string name, Mode mode, TimeNs fail_time)
      : Unit("Faulty", std::move(name)), mode_(mode), fail_time_(fail_time) {
    variables().Output("y", "s", &y_, "the time, until it fails", {});
  }
  StepResult DoStep(TimeNs t, TimeNs dt) override {
    ClearError();
    y_ = NsToSeconds(t + dt);
    // NaN and Inf are outputs at the end of the step; the other failures
    // happen in the step that starts at fail_time.
    switch (mode_) {
      case Mode::kNaN:
        if (t + dt == fail_time_) y_ = std::numeric_limits<double>::quiet_NaN();
        break;
      case Mode::kInf:
        if (t + dt == fail_time_) y_ = std::numeric_limits<double>::infinity();
        break;
      case Mode::kError:
        if (t == fail_time_) return Fail("actuator saturated");
        break;
      case Mode::kDiscard:
        if (t == fail_time_) {
          Fail("tolerance not met");
          return StepResult::kDiscard;
        }
        break;
      case Mode::kThrow:
        if (t == fail_time_) throw UnitError("solver diverged");
        break;
    }
    return StepResult::kOk;
  }

 private:
  Mode mode_;
  TimeNs fail_time_;
  double y_ = 0.0;
};

}  // namespace linesim::cosim::test_units
