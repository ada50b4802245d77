#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "models/moving_solids.h"

/// A person as linesim's workers are shaped (people::WorkerUnit): two legs
/// and a torso as vertical cylinders. The numbers and their sources are
/// here so that the worker unit and the loader's checks (a worker must not
/// start touching a robot) share them.
namespace linesim::models {

struct PersonBody {
  // At a scanner's height (0.18 m) the leg is the lower shank above the
  // ankle: ANSUR 1988 (Gordon et al. 1989), men, mean ankle circumference
  // 0.226 m and calf circumference 0.377 m; between them about 0.26 m with
  // work trousers, a radius of 0.045 m.
  double leg_radius_m = 0.045;
  // DIN 33402-2 (2005), men 50th percentile: hip breadth standing 0.36 m;
  // the legs' axes at ankle height are about the step width plus a shank
  // apart (step width 0.08-0.10 m, Perry & Burnfield 2010): 0.2 m.
  double leg_spacing_m = 0.2;
  // DIN 33402-2 (2005), men 50th percentile: stature 1.75 m, crotch height
  // 0.84 m (ANSUR 1988 gives 0.84 m too); shoulder breadth 0.40-0.46 m, so
  // a torso cylinder of radius 0.2 m.
  double crotch_height_m = 0.84;
  double torso_radius_m = 0.2;
  double stature_m = 1.75;
};

inline constexpr int kPersonCylinders = 3;  // left leg, right leg, torso

/// The cylinders (MovingCylinder values, at rest) of a person standing at
/// (x, y) facing `yaw`: the feet side by side, leg_spacing apart across the
/// heading (as WorkerUnit has a worker that stands).
inline std::array<double, kPersonCylinders * MovingCylinder::kValues> StandingPerson(
    const PersonBody& b, double x, double y, double yaw) {
  const double nx = -std::sin(yaw), ny = std::cos(yaw), half = 0.5 * b.leg_spacing_m;
  return {x + nx * half,
          y + ny * half,
          0.0,
          0.0,
          b.leg_radius_m,
          0.0,
          b.crotch_height_m,
          x - nx * half,
          y - ny * half,
          0.0,
          0.0,
          b.leg_radius_m,
          0.0,
          b.crotch_height_m,
          x,
          y,
          0.0,
          0.0,
          b.torso_radius_m,
          b.crotch_height_m,
          b.stature_m};
}

/// Distance of a vertical cylinder (MovingCylinder values) from a body box
/// (MovingBox values): the distance of its axis from the box's footprint
/// less its radius, 0 when they overlap; infinite when their heights have
/// nothing in common (a torso above a low base). As people::
/// PersonClearanceUnit measures the robot's clearance from a worker.
inline double CylinderBoxDistance(const double* cylinder, const double* box) {
  if (cylinder[MovingCylinder::kZTop] <= box[MovingBox::kZBottom] ||
      cylinder[MovingCylinder::kZBottom] >= box[MovingBox::kZTop]) {
    return std::numeric_limits<double>::infinity();
  }
  const double d =
      FootprintDistance(box, cylinder[MovingCylinder::kX], cylinder[MovingCylinder::kY]) -
      cylinder[MovingCylinder::kRadius];
  return std::max(d, 0.0);
}

}  // namespace linesim::models
