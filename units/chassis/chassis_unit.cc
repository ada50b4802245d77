#include "units/chassis/chassis_unit.h"

#include <ode/ode.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "cosim/parameter_checks.h"
#include "models/angle.h"
#include "units/chassis/floor_world.h"

namespace linesim::chassis {

namespace {

constexpr double kPi = std::numbers::pi;
// Settling before time zero: 300 steps of 1 ms is about ten periods of the
// slowest vertical mode (about 20 Hz with the default contacts) and its
// damping time.
constexpr double kSettleStepS = 1e-3;
constexpr int kSettleSteps = 300;
// Holding torque on every joint while settling, whatever brake_torque is.
constexpr double kSettleHoldTorqueNm = 1e4;
// Reals saved per body: position 3, quaternion 4, linear and angular
// velocity 3 each.
constexpr std::size_t kRealsPerBody = 13;

// Column c of an ODE rotation matrix (3 rows of 4).
void Column(const dReal* r, int c, double out[3]) {
  out[0] = r[c];
  out[1] = r[4 + c];
  out[2] = r[8 + c];
}

double Dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Yaw of a rotation matrix: heading of its x axis in the map plane.
double Yaw(const dReal* r) { return std::atan2(r[4], r[0]); }

bool AllFinite(const dReal* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace

struct ChassisUnit::Ode {
  std::unique_ptr<FloorWorld> floor;
  dBodyID body = nullptr;
  std::vector<dBodyID> wheels;
  std::vector<dJointID> joints;
  std::vector<dGeomID> geoms;
  // Internal step for which the suspension ERP/CFM were set (0: not yet).
  double suspension_h_s = 0.0;
  // Force limit the joint motors were set to (NaN: not yet).
  double motor_fmax_nm = std::numeric_limits<double>::quiet_NaN();

  Ode() = default;
  Ode(const Ode&) = delete;
  Ode& operator=(const Ode&) = delete;
  ~Ode() { Clear(); }

  // Geoms are not owned by the world; bodies and joints go with it.
  void Clear() {
    if (!floor) return;
    EnsureOdeForThisThread();
    floor->ClearGeoms();
    for (dGeomID g : geoms) dGeomDestroy(g);
    geoms.clear();
    wheels.clear();
    joints.clear();
    body = nullptr;
    floor.reset();
    suspension_h_s = 0.0;
    motor_fmax_nm = std::numeric_limits<double>::quiet_NaN();
  }

  // Every body, the base first.
  dBodyID Body(std::size_t i) const { return i == 0 ? body : wheels[i - 1]; }
  std::size_t BodyCount() const { return wheels.size() + 1; }
};

ChassisUnit::ChassisUnit(std::string name, int wheel_count, int belt_count)
    : cosim::Unit(kTypeName, std::move(name)),
      wheel_count_(wheel_count),
      belt_count_(belt_count),
      ode_(std::make_unique<Ode>()) {
  if (wheel_count < 1 || belt_count < 0) {
    throw cosim::UnitError(Where() + ": needs wheel_count >= 1 and belt_count >= 0, got " +
                           std::to_string(wheel_count) + " and " + std::to_string(belt_count));
  }
  const auto w = static_cast<std::size_t>(wheel_count);
  const auto b = static_cast<std::size_t>(belt_count);
  if (wheel_count == 4) {
    // Rob@Work 3's steering axes.
    wheel_x_.assign(models::raw3::kWheelXM.begin(), models::raw3::kWheelXM.end());
    wheel_y_.assign(models::raw3::kWheelYM.begin(), models::raw3::kWheelYM.end());
  } else {
    // No robot to copy: evenly on a circle of 0.3 m, a placeholder.
    for (std::size_t k = 0; k < w; ++k) {
      const double a = 2.0 * kPi * static_cast<double>(k) / static_cast<double>(w) + 0.25 * kPi;
      wheel_x_.push_back(0.3 * std::cos(a));
      wheel_y_.push_back(0.3 * std::sin(a));
    }
  }
  // Placeholder belts (scenarios set their own): along map x, 20 m x 3 m,
  // centred 2.5 m, 7.5 m, ... to the left of the origin.
  for (std::size_t k = 0; k < b; ++k) {
    belt_center_x_.push_back(0.0);
    belt_center_y_.push_back(2.5 + 5.0 * static_cast<double>(k));
    belt_length_.push_back(20.0);
    belt_width_.push_back(3.0);
    belt_direction_.push_back(0.0);
  }
  steer_torque_.assign(w, 0.0);
  drive_torque_.assign(w, 0.0);
  belt_velocity_.assign(2 * b, 0.0);
  steer_angle_.assign(w, 0.0);
  steer_rate_.assign(w, 0.0);
  drive_rate_.assign(w, 0.0);
  pose_.assign(3, 0.0);
  velocity_.assign(3, 0.0);
  body_velocity_.assign(3, 0.0);
  wheel_surface_.assign(w, -1.0);
  wheel_surface_velocity_.assign(2 * w, 0.0);
  wheel_contact_.assign(2 * w, 0.0);

  auto& v = variables();
  v.Parameter("body_length", "m", &body_length_, "body box length along base_link x");
  v.Parameter("body_width", "m", &body_width_, "body box width along base_link y");
  v.Parameter("body_height", "m", &body_height_, "body box height (for its inertia only)");
  v.Parameter("mass", "kg", &mass_, "total mass: body box plus all modules");
  v.Parameter("module_mass", "kg", &module_mass_,
              "mass of one steer+drive module (wheel, motors, housing), lumped into the wheel");
  v.Parameter("com_height", "m", &com_height_,
              "height of the body box's centre of mass above the floor (modules excluded)");
  v.Parameter("wheel_radius", "m", &wheel_radius_, "wheel radius (sphere contact geometry)");
  v.Parameter("wheel_x", "m", &wheel_x_, "steering axis x in base_link, per module");
  v.Parameter("wheel_y", "m", &wheel_y_, "steering axis y in base_link, per module");
  v.Parameter("steer_rotor_inertia", "kg.m2", &steer_rotor_inertia_,
              "steer motor rotor inertia seen at the steering joint (J_rotor N^2), added to the "
              "module inertia about the axes perpendicular to the axle");
  v.Parameter("drive_rotor_inertia", "kg.m2", &drive_rotor_inertia_,
              "drive motor rotor inertia seen at the wheel (J_rotor N^2), added about the axle");
  v.Parameter("steer_friction", "N.m.s/rad", &steer_friction_,
              "viscous friction of the steering joint");
  v.Parameter("drive_friction", "N.m.s/rad", &drive_friction_,
              "viscous friction of the wheel joint");
  v.Parameter("friction", "1", &friction_,
              "Coulomb coefficient of the wheels on floor and belts (force limit mu N)");
  v.Parameter("contact_stiffness", "N/m", &contact_stiffness_,
              "normal stiffness of one wheel contact");
  v.Parameter("contact_damping", "N.s/m", &contact_damping_, "normal damping of one wheel contact");
  v.Parameter("slip_damping", "N.s/m", &slip_damping_,
              "sliding contact: resistance to slip across its slip direction, bounded by "
              "friction x normal force (damps a step-to-step swing of the slip direction)");
  v.Parameter("suspension_stiffness", "N/m", &suspension_stiffness_,
              "stiffness of a module along its steering axis (hinge2 suspension)");
  v.Parameter("suspension_damping", "N.s/m", &suspension_damping_,
              "damping of a module along its steering axis");
  v.Parameter("brake_torque", "N.m", &brake_torque_,
              "holding torque of each joint's brake when brake is true");
  v.Parameter("substeps", &substeps_, "ODE steps per communication step");
  v.Parameter("initial_x", "m", &initial_x_, "base_link x in map at the start");
  v.Parameter("initial_y", "m", &initial_y_, "base_link y in map at the start");
  v.Parameter("initial_yaw", "rad", &initial_yaw_, "base_link yaw in map at the start");
  if (belt_count_ > 0) {
    v.Parameter("belt_center_x", "m", &belt_center_x_, "belt patch centre x in map");
    v.Parameter("belt_center_y", "m", &belt_center_y_, "belt patch centre y in map");
    v.Parameter("belt_length", "m", &belt_length_, "belt patch size along its direction");
    v.Parameter("belt_width", "m", &belt_width_, "belt patch size across its direction");
    v.Parameter("belt_direction", "rad", &belt_direction_,
                "direction of the belt patch's length axis in map, counter-clockwise from x");
  }

  v.Input("steer_torque", "N.m", &steer_torque_,
          "torque on each module about its steering axis, + counter-clockwise seen from above");
  v.Input("drive_torque", "N.m", &drive_torque_,
          "torque on each wheel about its axle, + drives it forward along its heading");
  if (belt_count_ > 0) {
    v.Input("belt_velocity", "m/s", &belt_velocity_,
            "surface velocity of each belt in map: vx, vy per belt");
  }
  v.Input("brake", &brake_,
          "true: both joints of every module held (velocity 0, up to brake_torque)");

  v.Output("steer_angle", "rad", &steer_angle_,
           "wheel heading relative to base_link x, in (-pi, pi]", {});
  v.Output("steer_rate", "rad/s", &steer_rate_, "steering rate relative to the body", {});
  v.Output("drive_rate", "rad/s", &drive_rate_,
           "wheel spin relative to its module, + rolling forward along the heading", {});
  v.Output("pose", "m", &pose_, "x, y (m) and yaw (rad, in (-pi, pi]) of base_link in map", {});
  v.Output("velocity", "m/s", &velocity_, "vx, vy (m/s) of base_link in map and yaw rate (rad/s)",
           {});
  v.Output("body_velocity", "m/s", &body_velocity_,
           "vx, vy (m/s) of base_link in base_link and yaw rate (rad/s)", {});
  v.Output("wheel_surface", "1", &wheel_surface_,
           "surface under each wheel: -1 no contact, 0 floor, k + 1 belt k", {});
  v.Output("wheel_surface_velocity", "m/s", &wheel_surface_velocity_,
           "velocity of the surface under each wheel in base_link: vx, vy per wheel (zero on "
           "the floor or without contact)",
           {});
  v.Output("wheel_contact", "m", &wheel_contact_,
           "contact point of each wheel in map (x, y), or the wheel centre without contact", {});
}

ChassisUnit::~ChassisUnit() = default;

std::vector<cosim::ParameterProblem> ChassisUnit::CheckParameters() const {
  cosim::ParameterChecks c;
  c.Positive("body_length", body_length_);
  c.Positive("body_width", body_width_);
  c.Positive("body_height", body_height_);
  c.Positive("mass", mass_);
  c.Positive("module_mass", module_mass_);
  if (mass_ > 0.0 && module_mass_ > 0.0 && !(wheel_count_ * module_mass_ < mass_)) {
    c.Add({"module_mass", std::nullopt,
           "times " + std::to_string(wheel_count_) + " modules must be less than mass " +
               cosim::FormatValue(mass_) + ", got " + cosim::FormatValue(module_mass_)});
  }
  c.Positive("com_height", com_height_);
  c.Positive("wheel_radius", wheel_radius_);
  c.Finite("wheel_x", wheel_x_);
  c.Finite("wheel_y", wheel_y_);
  c.NonNegative("steer_rotor_inertia", steer_rotor_inertia_);
  c.NonNegative("drive_rotor_inertia", drive_rotor_inertia_);
  c.NonNegative("steer_friction", steer_friction_);
  c.NonNegative("drive_friction", drive_friction_);
  c.NonNegative("friction", friction_);
  c.Positive("contact_stiffness", contact_stiffness_);
  c.NonNegative("contact_damping", contact_damping_);
  c.Positive("slip_damping", slip_damping_);
  c.Positive("suspension_stiffness", suspension_stiffness_);
  c.NonNegative("suspension_damping", suspension_damping_);
  c.NonNegative("brake_torque", brake_torque_);
  if (substeps_ < 1 || substeps_ > 1000) {
    c.Add({"substeps", std::nullopt, "must be 1 to 1000, got " + std::to_string(substeps_)});
  }
  c.Finite("initial_x", initial_x_);
  c.Finite("initial_y", initial_y_);
  c.Finite("initial_yaw", initial_yaw_);
  c.Finite("belt_center_x", belt_center_x_);
  c.Finite("belt_center_y", belt_center_y_);
  c.Positive("belt_length", belt_length_);
  c.Positive("belt_width", belt_width_);
  c.Finite("belt_direction", belt_direction_);
  return c.Take();
}

void ChassisUnit::Build() {
  EnsureOdeForThisThread();
  Ode& o = *ode_;
  o.Clear();
  o.floor = std::make_unique<FloorWorld>();
  FloorWorld& f = *o.floor;
  std::vector<BeltPatch> belts;
  for (std::size_t k = 0; k < belt_center_x_.size(); ++k) {
    belts.push_back({belt_center_x_[k], belt_center_y_[k], belt_length_[k], belt_width_[k],
                     belt_direction_[k]});
  }
  f.SetBelts(std::move(belts));
  f.SetSurface({friction_, contact_stiffness_, contact_damping_, slip_damping_});

  // Start with the contacts pressed in by equal shares of the weight, so
  // that the settle has little to do. The suspension starts unloaded (its
  // anchors coincide at creation) and settles too.
  const double n = static_cast<double>(wheel_count_);
  const double body_mass = mass_ - n * module_mass_;
  const double drop_m = mass_ * kGravityMps2 / n / contact_stiffness_;
  const double c = std::cos(initial_yaw_), s = std::sin(initial_yaw_);
  dMatrix3 rot;
  dRFromAxisAndAngle(rot, 0.0, 0.0, 1.0, initial_yaw_);

  o.body = dBodyCreate(f.world());
  dMass m;
  dMassSetBoxTotal(&m, body_mass, body_length_, body_width_, body_height_);
  dBodySetMass(o.body, &m);
  dBodySetPosition(o.body, initial_x_, initial_y_, com_height_ - drop_m);
  dBodySetRotation(o.body, rot);

  // Module inertia: a thin disc of the wheel radius (axial m r^2 / 2,
  // diametral m r^2 / 4) plus the reflected rotor inertias. The axle is the
  // wheel body's local y axis.
  const double r2 = wheel_radius_ * wheel_radius_;
  const double i_axle = 0.5 * module_mass_ * r2 + drive_rotor_inertia_;
  const double i_perp = 0.25 * module_mass_ * r2 + steer_rotor_inertia_;
  const double axle[3] = {-s, c, 0.0};
  const double up[3] = {0.0, 0.0, 1.0};
  for (std::size_t k = 0; k < static_cast<std::size_t>(wheel_count_); ++k) {
    const double x = initial_x_ + c * wheel_x_[k] - s * wheel_y_[k];
    const double y = initial_y_ + s * wheel_x_[k] + c * wheel_y_[k];
    const double z = wheel_radius_ - drop_m;
    dBodyID w = dBodyCreate(f.world());
    dMassSetParameters(&m, module_mass_, 0.0, 0.0, 0.0, i_perp, i_axle, i_perp, 0.0, 0.0, 0.0);
    dBodySetMass(w, &m);
    dBodySetPosition(w, x, y, z);
    dBodySetRotation(w, rot);
    dGeomID g = dCreateSphere(nullptr, wheel_radius_);
    dGeomSetBody(g, w);
    f.AddGeom(g);
    dJointID j = dJointCreateHinge2(f.world(), nullptr);
    dJointAttach(j, o.body, w);
    dJointSetHinge2Anchor(j, x, y, z);
    dJointSetHinge2Axes(j, up, axle);
    o.wheels.push_back(w);
    o.geoms.push_back(g);
    o.joints.push_back(j);
  }
}

void ChassisUnit::SetSuspension(double h_s) {
  if (h_s == ode_->suspension_h_s) return;
  const auto [erp, cfm] = ErpCfm(h_s, suspension_stiffness_, suspension_damping_);
  for (dJointID j : ode_->joints) {
    dJointSetHinge2Param(j, dParamSuspensionERP, erp);
    dJointSetHinge2Param(j, dParamSuspensionCFM, cfm);
  }
  ode_->suspension_h_s = h_s;
}

void ChassisUnit::SetJointMotors(bool hold, double max_torque_nm) {
  // A joint motor with target velocity 0 and force limit 0 adds no row.
  const double fmax = hold ? max_torque_nm : 0.0;
  if (fmax == ode_->motor_fmax_nm) return;
  ode_->motor_fmax_nm = fmax;
  for (dJointID j : ode_->joints) {
    dJointSetHinge2Param(j, dParamVel, 0.0);
    dJointSetHinge2Param(j, dParamFMax, fmax);
    dJointSetHinge2Param(j, dParamVel2, 0.0);
    dJointSetHinge2Param(j, dParamFMax2, fmax);
  }
}

void ChassisUnit::ApplyTorques() {
  const Ode& o = *ode_;
  double up[3], axle[3];
  Column(dBodyGetRotation(o.body), 2, up);
  const dReal* wb = dBodyGetAngularVel(o.body);
  for (std::size_t k = 0; k < o.wheels.size(); ++k) {
    const dBodyID w = o.wheels[k];
    Column(dBodyGetRotation(w), 1, axle);
    const dReal* ww = dBodyGetAngularVel(w);
    const double rel[3] = {ww[0] - wb[0], ww[1] - wb[1], ww[2] - wb[2]};
    const double steer = steer_torque_[k] - steer_friction_ * Dot(up, rel);
    const double drive = drive_torque_[k] - drive_friction_ * Dot(axle, rel);
    // The module turns the wheel and reacts on the body: equal and opposite.
    const double t[3] = {steer * up[0] + drive * axle[0], steer * up[1] + drive * axle[1],
                         steer * up[2] + drive * axle[2]};
    dBodyAddTorque(w, t[0], t[1], t[2]);
    dBodyAddTorque(o.body, -t[0], -t[1], -t[2]);
  }
}

void ChassisUnit::Settle() {
  FloorWorld& f = *ode_->floor;
  for (int k = 0; k < f.belt_count(); ++k) f.SetBeltVelocity(k, 0.0, 0.0);
  SetSuspension(kSettleStepS);
  SetJointMotors(true, kSettleHoldTorqueNm);
  for (int i = 0; i < kSettleSteps; ++i) {
    if (!f.Step(kSettleStepS))
      throw cosim::UnitError(Where() + ": dWorldStep failed while settling");
  }
  if (const std::string bad = NonFiniteState(); !bad.empty()) {
    throw cosim::UnitError(Where() + ": ODE state went non-finite while settling: " + bad);
  }
  // Move every body rigidly so that base_link is exactly at the initial
  // pose, and stop everything.
  const dReal* p0 = dBodyGetPosition(ode_->body);
  const double bx = p0[0], by = p0[1];
  const double turn = initial_yaw_ - Yaw(dBodyGetRotation(ode_->body));
  const double c = std::cos(turn), s = std::sin(turn);
  dQuaternion q_turn;
  dQFromAxisAndAngle(q_turn, 0.0, 0.0, 1.0, turn);
  for (std::size_t i = 0; i < ode_->BodyCount(); ++i) {
    const dBodyID b = ode_->Body(i);
    const dReal* p = dBodyGetPosition(b);
    const double dx = p[0] - bx, dy = p[1] - by;
    dBodySetPosition(b, initial_x_ + c * dx - s * dy, initial_y_ + s * dx + c * dy, p[2]);
    dQuaternion q;
    dQMultiply0(q, q_turn, dBodyGetQuaternion(b));
    dBodySetQuaternion(b, q);
    dBodySetLinearVel(b, 0.0, 0.0, 0.0);
    dBodySetAngularVel(b, 0.0, 0.0, 0.0);
  }
  // The contacts at the moved positions, for the outputs and the first step.
  f.Probe();
}

void ChassisUnit::Initialize() {
  std::vector<cosim::Value> parameters;
  for (const auto& info : variables().infos()) {
    if (info.causality == cosim::Causality::kParameter) {
      parameters.push_back(variables().GetValue(info.ref));
    }
  }
  // Settling uses only the parameters (belts still, joints held), so an
  // unchanged, unstepped world is already what a rebuild would give.
  if (!initialized_ || stepped_since_settle_ || parameters != settled_parameters_) {
    ThrowIfBadParameters();
    initialized_ = false;
    Build();
    Settle();
    settled_parameters_ = std::move(parameters);
    stepped_since_settle_ = false;
  }
  FloorWorld& f = *ode_->floor;
  for (int k = 0; k < f.belt_count(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    f.SetBeltVelocity(k, belt_velocity_[2 * kk], belt_velocity_[2 * kk + 1]);
  }
  ComputeOutputs();
  initialized_ = true;
}

std::string ChassisUnit::NonFiniteState() const {
  // Runs every step: the names are built only for a body that failed.
  const auto who = [](std::size_t i) {
    return i == 0 ? std::string("the body (outputs pose, velocity, body_velocity)")
                  : "wheel module " + std::to_string(i - 1) + " (outputs steer_angle[" +
                        std::to_string(i - 1) + "], steer_rate, drive_rate, wheel_contact)";
  };
  for (std::size_t i = 0; i < ode_->BodyCount(); ++i) {
    const dBodyID b = ode_->Body(i);
    if (!AllFinite(dBodyGetPosition(b), 3)) return "position of " + who(i);
    if (!AllFinite(dBodyGetQuaternion(b), 4)) return "orientation of " + who(i);
    if (!AllFinite(dBodyGetLinearVel(b), 3)) return "linear velocity of " + who(i);
    if (!AllFinite(dBodyGetAngularVel(b), 3)) return "angular velocity of " + who(i);
  }
  return {};
}

void ChassisUnit::ComputeOutputs() {
  const Ode& o = *ode_;
  const dReal* rb = dBodyGetRotation(o.body);
  const dReal* pb = dBodyGetPosition(o.body);
  const dReal* vb = dBodyGetLinearVel(o.body);
  const dReal* wb = dBodyGetAngularVel(o.body);
  const double yaw = Yaw(rb);
  const double c = std::cos(yaw), s = std::sin(yaw);
  pose_[0] = pb[0];
  pose_[1] = pb[1];
  pose_[2] = models::WrapAngle(yaw);
  velocity_[0] = vb[0];
  velocity_[1] = vb[1];
  velocity_[2] = wb[2];
  body_velocity_[0] = c * vb[0] + s * vb[1];
  body_velocity_[1] = -s * vb[0] + c * vb[1];
  body_velocity_[2] = wb[2];

  double ex[3], ey[3], ez[3], axle[3];
  Column(rb, 0, ex);
  Column(rb, 1, ey);
  Column(rb, 2, ez);
  for (std::size_t k = 0; k < o.wheels.size(); ++k) {
    const dBodyID w = o.wheels[k];
    Column(dBodyGetRotation(w), 1, axle);
    // Heading = axle x up; in base_link: (ax_y, -ax_x) of the axle there.
    steer_angle_[k] = models::WrapAngle(std::atan2(-Dot(axle, ex), Dot(axle, ey)));
    const dReal* ww = dBodyGetAngularVel(w);
    const double rel[3] = {ww[0] - wb[0], ww[1] - wb[1], ww[2] - wb[2]};
    steer_rate_[k] = Dot(ez, rel);
    drive_rate_[k] = Dot(axle, rel);
    const GeomContact& gc = o.floor->contact(static_cast<int>(k));
    wheel_surface_[k] = gc.surface;
    double vx = 0.0, vy = 0.0;
    o.floor->SurfaceVelocity(gc.surface, &vx, &vy);
    wheel_surface_velocity_[2 * k] = c * vx + s * vy;
    wheel_surface_velocity_[2 * k + 1] = -s * vx + c * vy;
    wheel_contact_[2 * k] = gc.x_m;
    wheel_contact_[2 * k + 1] = gc.y_m;
  }
}

cosim::StepResult ChassisUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  const auto at = [&]() { return " at t = " + cosim::FormatSeconds(t) + " s"; };
  // The master initialises every unit before stepping it, but after a failed
  // step the ODE world may be inconsistent (initialized_ is cleared there),
  // and it is not rebuilt until Initialize or RestoreState: refuse to step it.
  if (!initialized_) {
    return Fail(Where() + ": the ODE world needs Initialize or RestoreState (after a failed " +
                "step, or never initialised)" + at());
  }
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  EnsureOdeForThisThread();
  stepped_since_settle_ = true;
  FloorWorld& f = *ode_->floor;
  for (int k = 0; k < f.belt_count(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    f.SetBeltVelocity(k, belt_velocity_[2 * kk], belt_velocity_[2 * kk + 1]);
  }
  const double h_s = cosim::NsToSeconds(dt) / static_cast<double>(substeps_);
  SetSuspension(h_s);
  SetJointMotors(brake_, brake_torque_);
  try {
    for (std::int64_t i = 0; i < substeps_; ++i) {
      ApplyTorques();
      if (!f.Step(h_s)) return Fail(Where() + ": dWorldStep failed (out of memory)" + at());
    }
  } catch (const OdeError& e) {
    // The world may be inconsistent: only Initialize or RestoreState again.
    initialized_ = false;
    const std::string bad = NonFiniteState();
    return Fail(Where() + ": " + e.what() + at() +
                (bad.empty() ? std::string() : "; ODE state went non-finite: " + bad));
  }
  if (const std::string bad = NonFiniteState(); !bad.empty()) {
    initialized_ = false;
    return Fail(Where() + ": ODE state went non-finite" + at() + ": " + bad);
  }
  // FloorWorld::Step collided at the new positions already.
  ComputeOutputs();
  return cosim::StepResult::kOk;
}

void ChassisUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers = {initialized_ ? 1 : 0};
  state.reals.clear();
  if (!initialized_) return;
  state.reals.reserve(ode_->BodyCount() * kRealsPerBody);
  for (std::size_t i = 0; i < ode_->BodyCount(); ++i) {
    const dBodyID b = ode_->Body(i);
    for (const auto& [v, n] : {std::pair{dBodyGetPosition(b), 3},
                               {dBodyGetQuaternion(b), 4},
                               {dBodyGetLinearVel(b), 3},
                               {dBodyGetAngularVel(b), 3}}) {
      state.reals.insert(state.reals.end(), v, v + n);
    }
  }
}

void ChassisUnit::RestoreInternal(const cosim::UnitState& state) {
  stepped_since_settle_ = true;
  const std::size_t bodies = static_cast<std::size_t>(wheel_count_) + 1;
  const bool init = state.integers.size() == 1 && state.integers[0] != 0;
  const std::size_t reals = init ? bodies * kRealsPerBody : 0;
  if (state.integers.size() != 1 || state.reals.size() != reals) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected " + std::to_string(reals) + " and 1");
  }
  initialized_ = false;
  if (!init) return;
  // Parameters came back with the variables: the same build as Initialize,
  // then every body state exactly as saved.
  ThrowIfBadParameters();
  Build();
  const double* r = state.reals.data();
  for (std::size_t i = 0; i < bodies; ++i, r += kRealsPerBody) {
    const dBodyID b = ode_->Body(i);
    dBodySetPosition(b, r[0], r[1], r[2]);
    // dBodySetQuaternion renormalises, which may change the last bit; the
    // saved quaternion is already the normalised one ODE steps with, so it
    // and the rotation matrix derived from it (as dWorldStep derives it) are
    // written back unchanged. The pointers are ODE's own storage.
    dBodySetQuaternion(b, r + 3);
    auto* q = const_cast<dReal*>(dBodyGetQuaternion(b));
    for (int d = 0; d < 4; ++d) q[d] = r[3 + d];
    dQtoR(q, const_cast<dReal*>(dBodyGetRotation(b)));
    dBodySetLinearVel(b, r[7], r[8], r[9]);
    dBodySetAngularVel(b, r[10], r[11], r[12]);
  }
  // The contacts at the restored positions, for the next step.
  ode_->floor->Probe();
  initialized_ = true;
}

}  // namespace linesim::chassis
