#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/dc_motor_params.h"

// SUNDIALS' matrix type, declared here so that its headers stay private.
struct _generic_SUNMatrix;

namespace linesim::motors {

enum class MotorMode {
  /// Armature current and rotor speed are states; the load is a torque input.
  kFull,
  /// Only the armature current is a state; the output shaft speed is an input
  /// (from the chassis physics, which owns the mechanics).
  kCurrentOnly,
};

/// `count` brushed DC motors with gearboxes, integrated together in one
/// SUNDIALS CVODE system (BDF, band direct solver, analytic Jacobian).
///
///   L di/dt = V - R i - k_t w_r                     (both modes)
///   J_eff dw_r/dt = k_t i - b w_r + tau_load / (eta N)     (full mode)
///   J_eff = J_rotor + J_load / (eta N^2),  w_r = N w_out,
///   torque = eta N (k_t i - b w_r)   (delivered by the gearbox; rotor inertia
///                                      not included)
///
/// The gearbox loss is a constant efficiency on the torque passed from the
/// motor to the output, so the load side (torque and inertia) reflects to the
/// rotor divided by eta N and eta N^2. It is applied in both power directions
/// (a smooth, linear model; back-driving losses are not modelled).
///
/// Inputs are held constant over a communication step; a changed input is a
/// discontinuity, so CVODE is restarted (CVodeReInit) only when an input
/// changed bitwise, after a save or restore, after Initialize, or when the
/// step does not start where the last one ended. Otherwise it continues with
/// its history, which is far cheaper.
class DcMotorUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "dc_motor";

  /// Throws cosim::UnitError if count < 1. Every motor starts with the
  /// datasheet parameters of models::DcMotorParams; change them per motor
  /// through the table (or a model file).
  DcMotorUnit(std::string name, int count, MotorMode mode);
  ~DcMotorUnit() override;

  /// Validates the parameters against the rules declared with them (throws
  /// cosim::UnitError naming the unit, the variable, the element and the bad
  /// value, every one at once), sets the states to the initial values and
  /// computes the outputs.
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;
  /// Current-only mode: the torque follows a new shaft speed at once.
  void UpdateOutputs() override { ComputeOutputs(); }

  int count() const { return count_; }
  MotorMode mode() const { return mode_; }
  /// CVODE (re)starts so far: the first step, input changes, save/restore.
  std::int64_t cvode_restarts() const { return restarts_; }
  /// CVODE internal steps so far, summed over restarts.
  std::int64_t cvode_steps() const { return steps_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  // CVODE memory with its context, vectors, matrix and linear solver, and
  // the callbacks; defined in the .cc so that SUNDIALS stays private.
  struct Sundials;

  void EvalRhs(double t_s, const double* y, double* ydot) const;
  /// The band Jacobian: only the 2x2 (or 1x1) diagonal blocks are non-zero.
  void FillJacobian(::_generic_SUNMatrix* jac) const;

  /// Checks the parameters (throws) and derives from them what the
  /// integration needs: coefficients, tolerances, the hold.
  void DeriveFromParameters();
  void ComputeCoefficients();
  void ComputeOutputs();
  bool InputsChanged() const;
  void HoldInputs(cosim::TimeNs t);
  /// Advances CVODE from t0_s to t1_s (the step starting at t), restarting it
  /// from y_ first if asked; returns CVode's flag.
  int Integrate(cosim::TimeNs t, double t0_s, double t1_s, bool restart);
  /// SUNDIALS's lookup of a flag's name (a malloc'ed string).
  using FlagName = char* (*)(long int);
  /// Throws cosim::UnitError naming the unit, the SUNDIALS function, the time
  /// and the flag when `flag` is negative. `flag_name` names the flag: null
  /// is CVodeGetReturnFlagName (kept out of this header with SUNDIALS); the
  /// linear-solver functions pass CVodeGetLinReturnFlagName.
  void Check(int flag, const char* function, cosim::TimeNs t, FlagName flag_name = nullptr) const;
  std::string WorstState() const;
  /// Each motor's L / R as text ("2.7e-4" or "[2.7e-4, 1e-300]").
  std::string ElectricalTimeConstants() const;
  /// The voltage inputs as text, as ElectricalTimeConstants.
  std::string VoltageText() const;
  void SetTolerances();

  int count_;
  MotorMode mode_;
  int states_per_motor_;

  // Parameters (per motor unless scalar).
  std::vector<double> resistance_, inductance_, torque_constant_, rotor_inertia_, viscous_friction_,
      gear_ratio_, gear_efficiency_, load_inertia_, initial_current_, initial_speed_;
  // Measured global error is about 10 x rel_tol of a signal's range (under
  // 1e-7 in the tests), far below both the 1e-4 the tests demand and the coupling error
  // of a 1 ms zero-order hold; 1e-6 would cost about 0.65 x the steps. The
  // scaled abs_tol (3e-10 A, 3e-9 rad/s for the RE 40) only matters near
  // zero crossings.
  double rel_tol_ = 1e-8;
  double abs_tol_ = 1e-10;
  // Current-only mode: how the shaft speed is held over a step ("zero_order"
  // or "first_order"); see the parameter's description.
  std::string shaft_speed_hold_ = "zero_order";
  bool first_order_ = false;

  // Inputs.
  std::vector<double> voltage_, load_torque_, shaft_speed_;
  // Outputs.
  std::vector<double> current_, speed_, torque_;
  // Current-only mode: the torque-speed line over the next step, torque
  // line_torque_ + line_slope_ (w - line_rate_) at output shaft speed w.
  std::vector<double> line_torque_, line_rate_, line_slope_;

  // Right-hand side coefficients per motor, from the parameters.
  std::vector<double> di_di_, di_dw_, di_dv_, dw_di_, dw_dw_, dw_dload_;
  // Inputs as held over the current step (the right-hand side reads these).
  std::vector<double> held_voltage_, held_load_torque_, held_shaft_speed_;
  // First-order hold: slope of the shaft speed over the current step (from
  // the last two samples), the sample before the current one, and the step
  // start in seconds (the right-hand side needs the time since the sample).
  std::vector<double> shaft_slope_, previous_shaft_speed_;
  double held_since_s_ = 0.0;
  cosim::TimeNs previous_sample_time_ = -1;
  // State at the end of the last step (current, rotor speed per motor).
  std::vector<double> y_;
  cosim::TimeNs end_time_ = 0;
  bool initialized_ = false;
  // Set when the integrator history no longer matches y_ and the held
  // inputs: the next DoStep must restart CVODE. Mutable because SaveState
  // is const and a save point must become a restart point (see
  // SaveInternal).
  mutable bool restart_pending_ = true;

  std::int64_t restarts_ = 0;
  std::int64_t steps_ = 0;
  long steps_since_restart_ = 0;
  double t_reached_s_ = 0.0;  // where CVODE's last call ended

  std::unique_ptr<Sundials> sun_;
};

}  // namespace linesim::motors
