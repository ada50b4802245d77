#include "units/evaluation/robot_clearance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "models/moving_solids.h"

namespace linesim::evaluation {

namespace {

using models::MovingBox;

using Corners = std::array<std::array<double, 2>, 4>;

// A footprint with its yaw's cos and sin (taken once).
struct Footprint {
  explicit Footprint(const double* box)
      : x(box[MovingBox::kX]),
        y(box[MovingBox::kY]),
        c(std::cos(box[MovingBox::kYaw])),
        s(std::sin(box[MovingBox::kYaw])),
        hx(0.5 * box[MovingBox::kLength]),
        hy(0.5 * box[MovingBox::kWidth]) {}
  double x, y, c, s, hx, hy;

  Corners CornersOf() const {
    Corners out;
    const double signs[4][2] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}};
    for (std::size_t k = 0; k < 4; ++k) {
      const double px = signs[k][0] * hx, py = signs[k][1] * hy;
      out[k] = {x + c * px - s * py, y + s * px + c * py};
    }
    return out;
  }
  // How far point p lies outside the footprint along its two axes (0 for
  // an axis it lies within): its distance is the hypot of the two.
  std::array<double, 2> OutsideBy(const std::array<double, 2>& p) const {
    const double dx = p[0] - x, dy = p[1] - y;
    const double ex = std::abs(c * dx + s * dy) - hx, ey = std::abs(-s * dx + c * dy) - hy;
    return {std::max(ex, 0.0), std::max(ey, 0.0)};
  }
  // Half its diagonal: the radius of the circle around it.
  double Reach() const { return std::hypot(hx, hy); }
};

// Whether the footprints' projections on the axis (ux, uy) are disjoint.
bool Separates(const Corners& a, const Corners& b, double ux, double uy) {
  double a0 = std::numeric_limits<double>::max(), a1 = -a0, b0 = a0, b1 = -a0;
  for (std::size_t k = 0; k < 4; ++k) {
    const double pa = a[k][0] * ux + a[k][1] * uy, pb = b[k][0] * ux + b[k][1] * uy;
    a0 = std::min(a0, pa), a1 = std::max(a1, pa);
    b0 = std::min(b0, pb), b1 = std::max(b1, pb);
  }
  return a1 < b0 || b1 < a0;
}

// The distance between footprints a (with its corners and reach, taken
// once per step for the robot's own) and b.
double Distance(const Footprint& fa, const Corners& ca, double reach_a, const Footprint& fb) {
  // Far apart (centres further than the half diagonals): the corners
  // decide without the separating axes.
  const double reach = reach_a + fb.Reach();
  const Corners cb = fb.CornersOf();
  const bool separated = std::hypot(fb.x - fa.x, fb.y - fa.y) > reach ||
                         Separates(ca, cb, fa.c, fa.s) || Separates(ca, cb, -fa.s, fa.c) ||
                         Separates(ca, cb, fb.c, fb.s) || Separates(ca, cb, -fb.s, fb.c);
  if (!separated) return 0.0;
  // The nearest corner: by squared distance, then the hypot (the reported
  // distance, as before) of those that can tie with it at double rounding,
  // not of all eight.
  std::array<std::array<double, 2>, 8> out;
  std::array<double, 8> squared;
  double least = std::numeric_limits<double>::max();
  for (std::size_t k = 0; k < 4; ++k) {
    out[2 * k] = fb.OutsideBy(ca[k]);
    out[2 * k + 1] = fa.OutsideBy(cb[k]);
  }
  for (std::size_t k = 0; k < 8; ++k) {
    squared[k] = out[k][0] * out[k][0] + out[k][1] * out[k][1];
    least = std::min(least, squared[k]);
  }
  double best = std::numeric_limits<double>::max();
  for (std::size_t k = 0; k < 8; ++k) {
    if (squared[k] <= least * (1.0 + 1e-9)) best = std::min(best, std::hypot(out[k][0], out[k][1]));
  }
  return best;
}

}  // namespace

double RobotClearanceUnit::FootprintDistance(const double* a, const double* b) {
  const Footprint fa(a), fb(b);
  return Distance(fa, fa.CornersOf(), fa.Reach(), fb);
}

RobotClearanceUnit::RobotClearanceUnit(std::string name, int bodies)
    : cosim::Unit(kTypeName, std::move(name)), bodies_(bodies) {
  if (bodies_ < 2) throw cosim::UnitError(Where() + ": needs at least two robots");
  const auto n = static_cast<std::size_t>(bodies_);
  boxes_.assign(n * MovingBox::kValues, 0.0);
  robot_distance_.assign(n, 0.0);
  robot_collisions_.assign(n, 0.0);
  contact_before_.assign(n, 0);
  auto& v = variables();
  v.Parameter("contact_distance", "m", &contact_distance_,
              "bodies closer than this are in contact (the gap two pushing bodies keep: their "
              "relative speed times the master step)",
              cosim::Rule::NonNegative());
  v.Parameter("own", &own_, "index of this robot's body in `bodies`",
              cosim::Rule::Range(0, static_cast<double>(bodies_ - 1)));
  v.Input("bodies", "m, rad, m/s, rad/s", &boxes_,
          "every robot's body (its chassis' body_box: [x, y, yaw, vx, vy, yaw_rate, length, "
          "width, z_bottom, z_top] in map), one after another");
  v.Output("distance", "m", &distance_, "distance from the body to the nearest other robot",
           {});
  v.Output("min_distance", "m", &min_distance_, "smallest distance so far", {});
  v.Output("nearest", "1", &nearest_, "index in `bodies` of the nearest other robot (-1: none)",
           {});
  v.Output("collisions", "1", &collisions_, "robot-robot contact events so far", {});
  v.Output("robot_distance", "m", &robot_distance_,
           "distance to each robot of `bodies` (-1 for its own)", {});
  v.Output("robot_collisions", "1", &robot_collisions_,
           "contact events with each robot of `bodies` so far (the pair this robot - robot k)",
           {});
}

void RobotClearanceUnit::Evaluate() {
  const auto self = static_cast<std::size_t>(own_);
  const double* own = boxes_.data() + self * MovingBox::kValues;
  // The own footprint's trigonometry, corners and reach, once per step.
  const Footprint own_print(own);
  const Corners own_corners = own_print.CornersOf();
  const double own_reach = own_print.Reach();
  distance_ = std::numeric_limits<double>::max();
  nearest_ = -1.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(bodies_); ++k) {
    if (k == self) {
      robot_distance_[k] = -1.0;
      contact_before_[k] = 0;
      continue;
    }
    const double* other = boxes_.data() + k * MovingBox::kValues;
    const bool absent = !(other[MovingBox::kLength] > 0.0 && other[MovingBox::kWidth] > 0.0);
    const bool apart_in_height = other[MovingBox::kZTop] < own[MovingBox::kZBottom] ||
                                 other[MovingBox::kZBottom] > own[MovingBox::kZTop];
    const double d = absent || apart_in_height
                         ? std::numeric_limits<double>::max()
                         : Distance(own_print, own_corners, own_reach, Footprint(other));
    robot_distance_[k] = d;
    if (d < distance_) {
      distance_ = d;
      nearest_ = static_cast<double>(k);
    }
    const bool contact = d <= contact_distance_;
    if (contact && !contact_before_[k]) {
      robot_collisions_[k] += 1.0;
      collisions_ += 1.0;
    }
    contact_before_[k] = contact ? 1 : 0;
  }
  min_distance_ = std::min(min_distance_, distance_);
}

void RobotClearanceUnit::Initialize() {
  ThrowIfBadParameters();
  std::fill(contact_before_.begin(), contact_before_.end(), 0);
  std::fill(robot_collisions_.begin(), robot_collisions_.end(), 0.0);
  collisions_ = 0.0;
  min_distance_ = std::numeric_limits<double>::max();
  Evaluate();
}

cosim::StepResult RobotClearanceUnit::DoStep(cosim::TimeNs t, cosim::TimeNs) {
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  Evaluate();
  return cosim::StepResult::kOk;
}

void RobotClearanceUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers.assign(contact_before_.begin(), contact_before_.end());
}

void RobotClearanceUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.integers.size() != contact_before_.size()) {
    throw cosim::UnitError(Where() + ": saved state has " +
                           std::to_string(state.integers.size()) + " contact flags, expected " +
                           std::to_string(contact_before_.size()));
  }
  for (std::size_t k = 0; k < contact_before_.size(); ++k) {
    contact_before_[k] = static_cast<std::uint8_t>(state.integers[k]);
  }
}

}  // namespace linesim::evaluation
