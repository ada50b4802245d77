#include "units/motors/dc_motor_unit.h"

#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunmatrix/sunmatrix_band.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <utility>

namespace linesim::motors {

namespace {

// Bitwise, so that -0.0 vs 0.0 or a NaN payload also count as a change.
bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace

struct DcMotorUnit::Sundials {
  SUNContext ctx = nullptr;
  N_Vector y = nullptr;
  N_Vector abstol = nullptr;
  SUNMatrix matrix = nullptr;
  SUNLinearSolver solver = nullptr;
  void* cvode = nullptr;
  // Last error message from CVODE's error handler (CVODE would print it
  // otherwise; we put it into the exception instead).
  std::string message;

  Sundials() = default;
  Sundials(const Sundials&) = delete;
  Sundials& operator=(const Sundials&) = delete;
  ~Sundials() {
    if (cvode) CVodeFree(&cvode);
    if (solver) SUNLinSolFree(solver);
    if (matrix) SUNMatDestroy(matrix);
    if (abstol) N_VDestroy(abstol);
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }

  static int Rhs(realtype t, N_Vector y, N_Vector ydot, void* user_data) {
    static_cast<const DcMotorUnit*>(user_data)->EvalRhs(t, N_VGetArrayPointer(y),
                                                        N_VGetArrayPointer(ydot));
    return 0;
  }

  static int Jacobian(realtype, N_Vector, N_Vector, SUNMatrix jac, void* user_data, N_Vector,
                      N_Vector, N_Vector) {
    static_cast<const DcMotorUnit*>(user_data)->FillJacobian(jac);
    return 0;
  }

  static void ErrorHandler(int error_code, const char* module, const char* function, char* msg,
                           void* user_data) {
    if (error_code >= 0) return;  // warnings are not failures
    static_cast<Sundials*>(user_data)->message = std::string(module) + "/" + function + ": " + msg;
  }
};

DcMotorUnit::DcMotorUnit(std::string name, int count, MotorMode mode)
    : cosim::Unit(kTypeName, std::move(name)),
      count_(count),
      mode_(mode),
      states_per_motor_(mode == MotorMode::kFull ? 2 : 1) {
  if (count < 1) {
    throw cosim::UnitError(Where() + ": count must be at least 1, got " + std::to_string(count));
  }
  const auto n = static_cast<std::size_t>(count);
  const bool full = mode_ == MotorMode::kFull;
  const models::DcMotorParams defaults;
  resistance_.assign(n, defaults.resistance_ohm);
  inductance_.assign(n, defaults.inductance_h);
  torque_constant_.assign(n, defaults.torque_constant_nm_per_a);
  rotor_inertia_.assign(n, defaults.rotor_inertia_kgm2);
  viscous_friction_.assign(n, defaults.viscous_friction_nms_per_rad);
  gear_ratio_.assign(n, defaults.gear_ratio);
  gear_efficiency_.assign(n, defaults.gear_efficiency);
  initial_current_.assign(n, 0.0);
  voltage_.assign(n, 0.0);
  current_.assign(n, 0.0);
  torque_.assign(n, 0.0);
  if (full) {
    load_inertia_.assign(n, defaults.load_inertia_kgm2);
    initial_speed_.assign(n, 0.0);
    load_torque_.assign(n, 0.0);
    speed_.assign(n, 0.0);
  } else {
    shaft_speed_.assign(n, 0.0);
    line_torque_.assign(n, 0.0);
    line_rate_.assign(n, 0.0);
    line_slope_.assign(n, 0.0);
    shaft_slope_.assign(n, 0.0);
    previous_shaft_speed_.assign(n, 0.0);
  }

  auto& v = variables();
  v.Parameter("resistance", "Ohm", &resistance_, "armature (terminal) resistance",
              cosim::Rule::Positive());
  v.Parameter("inductance", "H", &inductance_, "armature (terminal) inductance",
              cosim::Rule::Positive());
  v.Parameter("torque_constant", "N.m/A", &torque_constant_,
              "torque constant k_t, equal to the back-EMF constant in V.s/rad",
              cosim::Rule::Positive());
  v.Parameter("rotor_inertia", "kg.m2", &rotor_inertia_, "rotor inertia", cosim::Rule::Positive());
  v.Parameter("viscous_friction", "N.m.s/rad", &viscous_friction_,
              "viscous friction on the rotor, b (friction torque b * rotor speed)",
              cosim::Rule::NonNegative());
  v.Parameter("gear_ratio", "1", &gear_ratio_,
              "N: rotor revolutions per output revolution (1 = no gearbox)",
              cosim::Rule::Positive());
  v.Parameter("gear_efficiency", "1", &gear_efficiency_,
              "eta: fraction of the motor torque reaching the output",
              cosim::Rule::Range(0.0, false, 1.0, true));
  v.Parameter("initial_current", "A", &initial_current_, "armature current at the start",
              cosim::Rule::Finite());
  if (full) {
    v.Parameter("load_inertia", "kg.m2", &load_inertia_,
                "inertia at the gearbox output, reflected to the rotor as J / (eta N^2)",
                cosim::Rule::NonNegative());
    v.Parameter("initial_speed", "rad/s", &initial_speed_, "output shaft speed at the start",
                cosim::Rule::Finite());
  }
  if (!full) {
    v.Parameter("shaft_speed_hold", &shaft_speed_hold_,
                "zero_order: the shaft speed is held constant over a step and a new value "
                "restarts CVODE (exact for a piecewise-constant input); first_order: it is "
                "extrapolated along the slope of its last two samples and a new value does not "
                "restart CVODE (only a new voltage does), for a speed that varies continuously",
                cosim::Rule::OneOf({"zero_order", "first_order"}));
  }
  v.Parameter("rel_tol", "1", &rel_tol_, "CVODE relative tolerance", cosim::Rule::Positive());
  v.Parameter("abs_tol", "1", &abs_tol_,
              "CVODE absolute tolerance, relative to the stall current per volt 1 V/R "
              "and the no-load rotor speed per volt 1 V/k_t of each motor",
              cosim::Rule::Positive());

  v.Input("voltage", "V", &voltage_, "terminal voltage, held over a communication step");
  if (full) {
    v.Input("load_torque", "N.m", &load_torque_,
            "torque applied BY the load ON the output shaft: positive accelerates the shaft "
            "in the positive direction (a braking load has the opposite sign of speed)");
  } else {
    v.Input("shaft_speed", "rad/s", &shaft_speed_,
            "output shaft speed from the physics; rotor speed = gear_ratio * shaft_speed");
  }

  v.Output("current", "A", &current_, "armature current", {});
  if (full) {
    v.Output("speed", "rad/s", &speed_, "output shaft speed", {});
    v.Output("torque", "N.m", &torque_,
             "torque delivered by the gearbox, eta N (k_t i - b w_rotor); rotor "
             "inertia not included",
             {});
  } else {
    v.Output("torque", "N.m", &torque_,
             "torque delivered by the gearbox, eta N (k_t i - b N shaft_speed); rotor "
             "inertia not included",
             {"shaft_speed"});
    // The motor's torque falls with its shaft speed (back-EMF, friction),
    // within a step too. A physics unit that applies torque as given over a
    // step makes that damping explicit: a light wheel on a creeping tyre
    // then oscillates out of bounds. These give it the line to apply
    // implicitly (the chassis as its joint's motor row).
    v.Output("line_torque", "N.m", &line_torque_,
             "torque on the torque-speed line at line_rate: eta N (k_t i - b N line_rate)", {});
    v.Output("line_rate", "rad/s", &line_rate_,
             "output shaft speed the current was integrated against at the step's end (the "
             "held or extrapolated shaft_speed)",
             {});
    v.Output("line_slope", "N.m.s/rad", &line_slope_,
             "d torque / d shaft speed with the current in equilibrium, -eta N^2 (b + k_t^2 / "
             "R): L / R (0.28 ms for the RE 40) is short against a step",
             {});
  }

  const auto size = static_cast<sunindextype>(count_ * states_per_motor_);
  y_.assign(static_cast<std::size_t>(size), 0.0);
  sun_ = std::make_unique<Sundials>();
  if (SUNContext_Create(nullptr, &sun_->ctx) != 0) {
    throw cosim::UnitError(Where() + ": SUNContext_Create failed");
  }
  sun_->y = N_VNew_Serial(size, sun_->ctx);
  sun_->abstol = N_VNew_Serial(size, sun_->ctx);
  // The motors are independent: the Jacobian is block diagonal, 2x2 blocks
  // (current, rotor speed) in full mode and 1x1 in current-only mode, so a
  // band matrix of half-bandwidth states_per_motor - 1 holds it exactly and
  // its LU costs O(n) instead of the dense O(n^3).
  const auto half_band = static_cast<sunindextype>(states_per_motor_ - 1);
  sun_->matrix = SUNBandMatrix(size, half_band, half_band, sun_->ctx);
  if (!sun_->y || !sun_->abstol || !sun_->matrix) {
    throw cosim::UnitError(Where() + ": SUNDIALS could not allocate vectors or matrix");
  }
  sun_->solver = SUNLinSol_Band(sun_->y, sun_->matrix, sun_->ctx);
  sun_->cvode = CVodeCreate(CV_BDF, sun_->ctx);
  if (!sun_->solver || !sun_->cvode) {
    throw cosim::UnitError(Where() + ": SUNDIALS could not create the solver");
  }
  // Fused vector kernels: fewer passes and calls per CVODE step, which for
  // a handful of states is most of its cost.
  Check(N_VEnableFusedOps_Serial(sun_->y, SUNTRUE), "N_VEnableFusedOps_Serial", 0);
  N_VConst(0.0, sun_->y);
  Check(CVodeSetErrHandlerFn(sun_->cvode, &Sundials::ErrorHandler, sun_.get()),
        "CVodeSetErrHandlerFn", 0);
  Check(CVodeInit(sun_->cvode, &Sundials::Rhs, 0.0, sun_->y), "CVodeInit", 0);
  Check(CVodeSetUserData(sun_->cvode, this), "CVodeSetUserData", 0);
  // The CVLS functions have their own flag names.
  Check(CVodeSetLinearSolver(sun_->cvode, sun_->solver, sun_->matrix), "CVodeSetLinearSolver", 0,
        &CVodeGetLinReturnFlagName);
  Check(CVodeSetJacFn(sun_->cvode, &Sundials::Jacobian), "CVodeSetJacFn", 0,
        &CVodeGetLinReturnFlagName);
  // The default of 500 steps per call is too few for long communication
  // steps right after a restart at tight tolerances.
  Check(CVodeSetMaxNumSteps(sun_->cvode, 100000), "CVodeSetMaxNumSteps", 0);
}

DcMotorUnit::~DcMotorUnit() = default;

void DcMotorUnit::Check(int flag, const char* function, cosim::TimeNs t, FlagName flag_name) const {
  if (flag >= 0) return;
  char* name = (flag_name ? flag_name : &CVodeGetReturnFlagName)(flag);
  std::string text = Where() + ": " + function + " failed at t = " + cosim::FormatSeconds(t) +
                     " s with " + (name ? name : std::to_string(flag));
  std::free(name);
  if (sun_ && !sun_->message.empty()) {
    text += " (" + sun_->message + ")";
    sun_->message.clear();
  }
  throw cosim::UnitError(text);
}

// After a failed CVode call, the state to blame: one whose derivative is
// not finite at the last state (an absurd input or parameter), else the one
// with the largest weighted local error estimate.
std::string DcMotorUnit::ElectricalTimeConstants() const {
  std::string text;
  for (std::size_t k = 0; k < inductance_.size(); ++k) {
    text += (k ? ", " : "") + cosim::FormatValue(inductance_[k] / resistance_[k]);
  }
  return inductance_.size() == 1 ? text : "[" + text + "]";
}

std::string DcMotorUnit::VoltageText() const {
  std::string text;
  for (std::size_t k = 0; k < voltage_.size(); ++k) {
    text += (k ? ", " : "") + cosim::FormatValue(voltage_[k]);
  }
  return voltage_.size() == 1 ? text : "[" + text + "]";
}

std::string DcMotorUnit::WorstState() const {
  const auto state_name = [&](std::size_t j) {
    const std::size_t motor = j / static_cast<std::size_t>(states_per_motor_);
    const bool is_current = j % static_cast<std::size_t>(states_per_motor_) == 0;
    return std::string(is_current ? "current" : "rotor speed (output 'speed')") + "[" +
           std::to_string(motor) + "]";
  };
  std::vector<double> ydot(y_.size());
  EvalRhs(cosim::NsToSeconds(end_time_), y_.data(), ydot.data());
  for (std::size_t j = 0; j < y_.size(); ++j) {
    if (!std::isfinite(ydot[j])) {
      return "the derivative of " + state_name(j) + " is " + cosim::FormatValue(ydot[j]) +
             " (check the inputs)";
    }
  }
  N_Vector weights = N_VClone(sun_->y);
  N_Vector errors = N_VClone(sun_->y);
  std::string text;
  if (weights && errors && CVodeGetErrWeights(sun_->cvode, weights) == CV_SUCCESS &&
      CVodeGetEstLocalErrors(sun_->cvode, errors) == CV_SUCCESS) {
    const double* w = N_VGetArrayPointer(weights);
    const double* e = N_VGetArrayPointer(errors);
    std::size_t worst = 0;
    double worst_value = -1.0;
    for (std::size_t j = 0; j < y_.size(); ++j) {
      const double v = std::abs(e[j] * w[j]);
      if (!(v <= worst_value)) {  // also picks a NaN
        worst = j;
        worst_value = v;
      }
    }
    text = "largest local error in " + state_name(worst);
  }
  if (weights) N_VDestroy(weights);
  if (errors) N_VDestroy(errors);
  return text;
}

void DcMotorUnit::ComputeCoefficients() {
  const auto n = static_cast<std::size_t>(count_);
  di_di_.resize(n);
  di_dw_.resize(n);
  di_dv_.resize(n);
  dw_di_.assign(n, 0.0);
  dw_dw_.assign(n, 0.0);
  dw_dload_.assign(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double inv_l = 1.0 / inductance_[k];
    di_di_[k] = -resistance_[k] * inv_l;
    di_dw_[k] = -torque_constant_[k] * inv_l;
    di_dv_[k] = inv_l;
    if (mode_ == MotorMode::kCurrentOnly) {
      line_slope_[k] =
          -gear_efficiency_[k] * gear_ratio_[k] * gear_ratio_[k] *
          (viscous_friction_[k] + torque_constant_[k] * torque_constant_[k] / resistance_[k]);
    }
    if (mode_ == MotorMode::kFull) {
      const double n_eta = gear_ratio_[k] * gear_efficiency_[k];
      const double j_eff = rotor_inertia_[k] + load_inertia_[k] / (n_eta * gear_ratio_[k]);
      dw_di_[k] = torque_constant_[k] / j_eff;
      dw_dw_[k] = -viscous_friction_[k] / j_eff;
      dw_dload_[k] = 1.0 / (n_eta * j_eff);
    }
  }
}

void DcMotorUnit::SetTolerances() {
  // abs_tol is scaled per state by what 1 V produces (stall current 1 V/R,
  // no-load rotor speed 1 V/k_t), so one number suits motors of any size.
  double* a = N_VGetArrayPointer(sun_->abstol);
  for (int k = 0; k < count_; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    a[k * states_per_motor_] = abs_tol_ / resistance_[kk];
    if (mode_ == MotorMode::kFull) a[k * states_per_motor_ + 1] = abs_tol_ / torque_constant_[kk];
  }
  Check(CVodeSVtolerances(sun_->cvode, rel_tol_, sun_->abstol), "CVodeSVtolerances", end_time_);
}

void DcMotorUnit::EvalRhs(double t_s, const double* y, double* ydot) const {
  if (mode_ == MotorMode::kFull) {
    for (int k = 0; k < count_; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      const double i = y[2 * k];
      const double w = y[2 * k + 1];
      ydot[2 * k] = di_di_[kk] * i + di_dw_[kk] * w + di_dv_[kk] * held_voltage_[kk];
      ydot[2 * k + 1] = dw_di_[kk] * i + dw_dw_[kk] * w + dw_dload_[kk] * held_load_torque_[kk];
    }
  } else {
    for (int k = 0; k < count_; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      const double shaft = first_order_
                               ? held_shaft_speed_[kk] + shaft_slope_[kk] * (t_s - held_since_s_)
                               : held_shaft_speed_[kk];
      const double w = gear_ratio_[kk] * shaft;
      ydot[k] = di_di_[kk] * y[k] + di_dw_[kk] * w + di_dv_[kk] * held_voltage_[kk];
    }
  }
}

void DcMotorUnit::FillJacobian(SUNMatrix jac) const {
  SUNMatZero(jac);
  for (int k = 0; k < count_; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (mode_ == MotorMode::kFull) {
      SM_ELEMENT_B(jac, 2 * k, 2 * k) = di_di_[kk];
      SM_ELEMENT_B(jac, 2 * k, 2 * k + 1) = di_dw_[kk];
      SM_ELEMENT_B(jac, 2 * k + 1, 2 * k) = dw_di_[kk];
      SM_ELEMENT_B(jac, 2 * k + 1, 2 * k + 1) = dw_dw_[kk];
    } else {
      SM_ELEMENT_B(jac, k, k) = di_di_[kk];
    }
  }
}

void DcMotorUnit::ComputeOutputs() {
  for (int k = 0; k < count_; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const double i = y_[static_cast<std::size_t>(k * states_per_motor_)];
    double w_rotor;
    if (mode_ == MotorMode::kFull) {
      w_rotor = y_[static_cast<std::size_t>(2 * k + 1)];
      speed_[kk] = w_rotor / gear_ratio_[kk];
    } else {
      // Feedthrough: the torque uses the shaft speed input as it is now.
      w_rotor = gear_ratio_[kk] * shaft_speed_[kk];
      line_torque_[kk] =
          gear_efficiency_[kk] * gear_ratio_[kk] *
          (torque_constant_[kk] * i - viscous_friction_[kk] * gear_ratio_[kk] * line_rate_[kk]);
    }
    current_[kk] = i;
    torque_[kk] = gear_efficiency_[kk] * gear_ratio_[kk] *
                  (torque_constant_[kk] * i - viscous_friction_[kk] * w_rotor);
  }
}

void DcMotorUnit::DeriveFromParameters() {
  ThrowIfBadParameters();
  ComputeCoefficients();
  SetTolerances();
  first_order_ = mode_ == MotorMode::kCurrentOnly && shaft_speed_hold_ == "first_order";
}

void DcMotorUnit::Initialize() {
  DeriveFromParameters();
  previous_sample_time_ = -1;
  for (int k = 0; k < count_; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    y_[static_cast<std::size_t>(k * states_per_motor_)] = initial_current_[kk];
    if (mode_ == MotorMode::kFull) {
      y_[static_cast<std::size_t>(2 * k + 1)] = gear_ratio_[kk] * initial_speed_[kk];
    }
  }
  line_rate_ = shaft_speed_;
  ComputeOutputs();
  initialized_ = true;
  restart_pending_ = true;
}

bool DcMotorUnit::InputsChanged() const {
  if (!SameBits(voltage_, held_voltage_)) return true;
  if (mode_ == MotorMode::kFull) return !SameBits(load_torque_, held_load_torque_);
  // Under a first-order hold the shaft speed is continuous: CVODE's error
  // control absorbs the small mismatch between the extrapolated and the new
  // sample, so a new speed is no discontinuity.
  return !first_order_ && !SameBits(shaft_speed_, held_shaft_speed_);
}

void DcMotorUnit::HoldInputs(cosim::TimeNs t) {
  held_voltage_ = voltage_;
  held_load_torque_ = load_torque_;
  if (first_order_) {
    // Slope from the previous sample (saved with the state, so a restored
    // unit continues alike); before the first sample, or after a jump back
    // in time, hold to zero order once.
    const bool have_previous = previous_sample_time_ >= 0 && previous_sample_time_ < t;
    const double span_s = cosim::NsToSeconds(t - previous_sample_time_);
    for (std::size_t k = 0; k < shaft_speed_.size(); ++k) {
      shaft_slope_[k] = have_previous ? (shaft_speed_[k] - previous_shaft_speed_[k]) / span_s : 0.0;
    }
    previous_shaft_speed_ = shaft_speed_;
    previous_sample_time_ = t;
    held_since_s_ = cosim::NsToSeconds(t);
  }
  held_shaft_speed_ = shaft_speed_;
}

int DcMotorUnit::Integrate(cosim::TimeNs t, double t0_s, double t1_s, bool restart) {
  if (restart) {
    // Count the steps since the last restart first (a failed attempt's too).
    long nst = 0;
    Check(CVodeGetNumSteps(sun_->cvode, &nst), "CVodeGetNumSteps", t);
    steps_ += nst - steps_since_restart_;
    std::copy(y_.begin(), y_.end(), N_VGetArrayPointer(sun_->y));
    Check(CVodeReInit(sun_->cvode, t0_s, sun_->y), "CVodeReInit", t);
    ++restarts_;
    steps_since_restart_ = 0;
  }
  Check(CVodeSetStopTime(sun_->cvode, t1_s), "CVodeSetStopTime", t);
  t_reached_s_ = t0_s;
  return CVode(sun_->cvode, t1_s, sun_->y, &t_reached_s_, CV_NORMAL);
}

cosim::StepResult DcMotorUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  // The right-hand side's coefficients exist only after Initialize.
  if (!initialized_) return Fail(Where() + ": DoStep called before Initialize");
  if (!InputsFinite(t)) return cosim::StepResult::kError;

  // Time in CVODE is double seconds converted from the integer ns each step,
  // never accumulated.
  const double t0_s = cosim::NsToSeconds(t);
  const double t1_s = cosim::NsToSeconds(t + dt);
  const bool restart = restart_pending_ || t != end_time_ || InputsChanged();
  // Until this step succeeds, CVODE's history no longer matches y_.
  restart_pending_ = true;
  if (restart || first_order_) HoldInputs(t);
  int flag = Integrate(t, t0_s, t1_s, restart);
  if (flag < 0 && !restart) {
    // A first-order hold met a jump in shaft speed (a wheel touching down,
    // a collision) too large for CVODE's error control: redo the step from
    // its start as a restart, as a zero-order hold would.
    sun_->message.clear();
    flag = Integrate(t, t0_s, t1_s, true);
  }
  if (flag < 0) {
    sun_->message += (sun_->message.empty() ? "" : "; ") + WorstState();
    Check(flag, "CVode", t);
  }
  long nst = 0;
  Check(CVodeGetNumSteps(sun_->cvode, &nst), "CVodeGetNumSteps", t);
  // A success that is not one: CVODE says it reached the step's end but did
  // not get there, or got there in no step at all, or with its step size
  // collapsed to rounding of the time (a time constant beyond double
  // precision, such as an inductance of 1e-300 H): the states would stay
  // frozen while the run reports ok.
  double h_last = 0.0;
  Check(CVodeGetLastStep(sun_->cvode, &h_last), "CVodeGetLastStep", t);
  const double resolvable_s = 64.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, t1_s);
  if (t_reached_s_ != t1_s || nst == steps_since_restart_ || !(std::abs(h_last) > resolvable_s)) {
    return Fail(Where() + ": CVODE did not integrate the step from " + cosim::FormatSeconds(t) +
                " s (reached " + cosim::FormatValue(t_reached_s_) + " s after " +
                std::to_string(nst - steps_since_restart_) + " internal steps, the last of " +
                cosim::FormatValue(h_last) +
                " s): a state changes faster than double precision resolves (electrical time "
                "constants L / R = " +
                ElectricalTimeConstants() + " s; voltage " + VoltageText() + " V)");
  }
  steps_ += nst - steps_since_restart_;
  steps_since_restart_ = nst;

  const double* y = N_VGetArrayPointer(sun_->y);
  std::copy(y, y + y_.size(), y_.begin());
  end_time_ = t + dt;
  if (mode_ == MotorMode::kCurrentOnly) {
    for (std::size_t k = 0; k < line_rate_.size(); ++k) {
      line_rate_[k] = held_shaft_speed_[k];
      if (first_order_) line_rate_[k] += shaft_slope_[k] * (t1_s - held_since_s_);
    }
  }
  ComputeOutputs();
  restart_pending_ = false;
  return cosim::StepResult::kOk;
}

// CVODE's history (Nordsieck array, order, step size) cannot be saved, so a
// save point is made a restart point: the state vector is saved, and the
// next DoStep of this unit restarts CVODE from it, exactly as a unit restored
// from this state will. Both then continue bit for bit alike.
void DcMotorUnit::SaveInternal(cosim::UnitState& state) const {
  // The first-order hold's previous sample decides the next slope, so it is
  // state too.
  state.reals = y_;
  state.reals.insert(state.reals.end(), previous_shaft_speed_.begin(), previous_shaft_speed_.end());
  state.integers = {end_time_, initialized_ ? 1 : 0, previous_sample_time_};
  restart_pending_ = true;
}

void DcMotorUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t reals = y_.size() + previous_shaft_speed_.size();
  if (state.reals.size() != reals || state.integers.size() != 3) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected " + std::to_string(reals) + " and 3");
  }
  const auto split = state.reals.begin() + static_cast<std::ptrdiff_t>(y_.size());
  y_.assign(state.reals.begin(), split);
  previous_shaft_speed_.assign(split, state.reals.end());
  end_time_ = state.integers[0];
  initialized_ = state.integers[1] != 0;
  previous_sample_time_ = state.integers[2];
  // Parameters came back with the variables: derive from them again.
  if (initialized_) DeriveFromParameters();
  restart_pending_ = true;
}

}  // namespace linesim::motors
