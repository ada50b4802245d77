#include "units/people/person_clearance_unit.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace linesim::people {

PersonClearanceUnit::PersonClearanceUnit(std::string name, int workers,
                                         std::vector<std::string> names)
    : cosim::Unit(kTypeName, std::move(name)), workers_(workers), names_(std::move(names)) {
  if (workers_ < 1) throw cosim::UnitError(Where() + ": needs at least one worker");
  const auto n = static_cast<std::size_t>(workers_);
  if (!names_.empty() && names_.size() != n) {
    throw cosim::UnitError(Where() + ": " + std::to_string(names_.size()) + " names for " +
                           std::to_string(n) + " workers");
  }
  for (std::size_t k = names_.size(); k < n; ++k) names_.push_back("worker " + std::to_string(k));
  worker_contact_time_.assign(n, 0.0);
  cylinders_.assign(n * kCylindersPerWorker * kCylinderValues, 0.0);
  worker_distance_.assign(n, 0.0);
  worker_collisions_.assign(n, 0.0);
  contact_before_.assign(n, 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  body_length_ = body_width_ = nan;
  using cosim::Rule;
  auto& v = variables();
  v.Parameter("body_length", "m", &body_length_, "body box length along base_link x",
              Rule::Positive().NoDefault());
  v.Parameter("body_width", "m", &body_width_, "body box width along base_link y",
              Rule::Positive().NoDefault());
  v.Parameter("body_z_min", "m", &body_z_min_, "bottom of the body above the floor",
              Rule::Finite());
  v.Parameter("body_z_max", "m", &body_z_max_, "top of the body above the floor",
              Rule::Finite());
  v.Input("position_3d", "m", &position_3d_, "base_link origin in map");
  v.Input("orientation", "1", &orientation_, "base_link in map, quaternion w x y z");
  v.Input("cylinders", "m, m/s", &cylinders_,
          "each worker's cylinders (people::WorkerUnit's `cylinders`), one worker after another");
  v.Output("distance", "m", &distance_, "distance from the body to the nearest worker", {});
  v.Output("min_distance", "m", &min_distance_, "smallest distance so far", {});
  v.Output("nearest", "1", &nearest_, "index of the nearest worker", {});
  v.Output("collisions", "1", &collisions_, "robot-person contact events so far", {});
  v.Output("worker_distance", "m", &worker_distance_, "distance to each worker", {});
  v.Output("worker_collisions", "1", &worker_collisions_,
           "contact events with each worker so far (the pair robot - worker k)", {});
  v.Output("contact_time", "s", &contact_time_,
           "time the body has touched a worker so far (the steps ending in contact)", {});
  v.Output("worker_contact_time", "s", &worker_contact_time_,
           "time the body has touched each worker so far", {});
}

double PersonClearanceUnit::DistanceToRectangle(double x, double y, double hx, double hy) {
  const double dx = std::max(std::abs(x) - hx, 0.0);
  const double dy = std::max(std::abs(y) - hy, 0.0);
  return std::hypot(dx, dy);
}

void PersonClearanceUnit::Evaluate(bool commit, cosim::TimeNs t, cosim::TimeNs dt) {
  const double w = orientation_[0], qx = orientation_[1], qy = orientation_[2],
               qz = orientation_[3];
  const double yaw = std::atan2(2.0 * (w * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double hx = 0.5 * body_length_, hy = 0.5 * body_width_;
  distance_ = std::numeric_limits<double>::max();
  nearest_ = -1.0;
  bool any_contact = false;
  for (int k = 0; k < workers_; ++k) {
    double best = std::numeric_limits<double>::max();
    for (int j = 0; j < kCylindersPerWorker; ++j) {
      const double* m =
          cylinders_.data() + (k * kCylindersPerWorker + j) * kCylinderValues;
      if (m[6] <= body_z_min_ || m[5] >= body_z_max_) continue;  // no height in common
      const double dx = m[0] - position_3d_[0], dy = m[1] - position_3d_[1];
      const double bx = c * dx + s * dy, by = -s * dx + c * dy;
      best = std::min(best, std::max(0.0, DistanceToRectangle(bx, by, hx, hy) - m[4]));
    }
    const auto ku = static_cast<std::size_t>(k);
    worker_distance_[ku] = best;
    if (best < distance_) {
      distance_ = best;
      nearest_ = k;
    }
    const bool contact = best <= 0.0;
    if (commit) {
      if (contact && !contact_before_[ku]) {
        worker_collisions_[ku] += 1.0;
        collisions_ += 1.0;
        Warn(t + dt, names_[ku] +
                         " touches the robot's body: contact with a person is not "
                         "modelled (neither is pushed; the body passes through), so "
                         "the motion from here on is not what a real contact gives");
      }
      if (contact) worker_contact_time_[ku] += cosim::NsToSeconds(dt);
      contact_before_[ku] = contact ? 1 : 0;
    }
    any_contact = any_contact || contact;
  }
  if (commit && any_contact) contact_time_ += cosim::NsToSeconds(dt);
  min_distance_ = std::min(min_distance_, distance_);
}

void PersonClearanceUnit::Initialize() {
  ThrowIfBadParameters();
  ClearWarnings();
  std::fill(contact_before_.begin(), contact_before_.end(), 0);
  std::fill(worker_collisions_.begin(), worker_collisions_.end(), 0.0);
  std::fill(worker_contact_time_.begin(), worker_contact_time_.end(), 0.0);
  collisions_ = contact_time_ = 0.0;
  min_distance_ = std::numeric_limits<double>::max();
  Evaluate(true, start_, 0);
}

cosim::StepResult PersonClearanceUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  Evaluate(true, t, dt);
  return cosim::StepResult::kOk;
}

void PersonClearanceUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers.assign(contact_before_.begin(), contact_before_.end());
}

void PersonClearanceUnit::RestoreInternal(const cosim::UnitState& state) {
  for (std::size_t k = 0; k < contact_before_.size() && k < state.integers.size(); ++k) {
    contact_before_[k] = static_cast<std::uint8_t>(state.integers[k]);
  }
}

}  // namespace linesim::people
