#pragma once

// The robots and scenes the chassis tests build, with the source of each
// number. The unit itself has no robot-specific defaults.

#include <memory>
#include <string>
#include <vector>

#include "cosim/unit.h"
#include "models/scene.h"
#include "units/chassis/chassis_unit.h"

namespace linesim::chassis::test_robots {

// ---------------------------------------------------------------------------
// Fraunhofer IPA Rob@Work 3 (paper 1 and the raw3-1 configuration).

/// Total mass: paper 1, Table I.
inline constexpr double kRaw3MassKg = 120.0;
/// Module mass and centre-of-mass height: ASSUMPTIONS of
/// models/robots/raw3.yaml (wheel, two motors, gears, housing; batteries
/// low).
inline constexpr double kRaw3ModuleMassKg = 5.0;
inline constexpr double kRaw3ComHeightM = 0.13;
/// Body planform 1.03 x 0.57 m (paper 1, Table I), 0.33 m high from its
/// underside 0.07 m above the floor (the public URDF's base mesh) to Table
/// I's 0.40 m: models/robots/raw3.yaml.
inline constexpr double kRaw3BodyM[3] = {1.03, 0.57, 0.33};
inline constexpr double kRaw3BodyBottomM = 0.07;
/// Wheel radius and steering-axis positions: raw3-1 Platform.ini
/// (ipa320/cob_robots).
inline constexpr double kRaw3WheelRadiusM = 0.080;
inline constexpr double kRaw3WheelXM[4] = {0.368, -0.368, -0.368, 0.368};
inline constexpr double kRaw3WheelYM[4] = {0.186, 0.134, -0.186, -0.134};
/// eta N^2 J_rotor: maxon RE 40 rotor 142 g.cm^2 (maxon data sheet, the
/// stand-in motor) through the drive gear 21 and the steer belt 4 (ipa320
/// cob_robots configuration) at the efficiencies 0.75 and 0.9 that
/// models/robots/raw3.yaml assumes; docs/references.md.
inline constexpr double kRaw3DriveRotorKgm2 = 0.75 * 21.0 * 21.0 * 142e-7;
inline constexpr double kRaw3SteerRotorKgm2 = 0.9 * 4.0 * 4.0 * 142e-7;

// ---------------------------------------------------------------------------
// Clearpath Husky A200 (husky_description URDF, Clearpath user manual).

/// Wheel radius 0.1651 m (URDF).
inline constexpr double kHuskyWheelRadiusM = 0.1651;
/// Half wheelbase: wheelbase 0.512 m (URDF and manual).
inline constexpr double kHuskyHalfBaseM = 0.256;
/// Half track: wheel separation 0.5708 m (URDF).
inline constexpr double kHuskyHalfTrackM = 0.2854;
/// Base box 0.9874 x 0.5709 x 0.2475 m (URDF), its bottom plate (the URDF's
/// base_link) wheel_radius - wheel_vertical_offset = 0.1651 - 0.03282 m
/// above the floor (the manual's 130 mm ground clearance).
inline constexpr double kHuskyBodyM[3] = {0.9874, 0.5709, 0.2475};
inline constexpr double kHuskyBodyBottomM = 0.1323;
/// Total 50 kg (manual spec table), 2.637 kg per wheel (URDF).
inline constexpr double kHuskyMassKg = 50.0;
inline constexpr double kHuskyWheelMassKg = 2.637;
/// Centre of mass: ASSUMPTION of models/robots/husky.yaml (com_height_m),
/// mid-height of the box over the manual's 130 mm ground clearance.
inline constexpr double kHuskyComHeightM = 0.130 + 0.5 * kHuskyBodyM[2];
/// Wheel contact mu 1.0 (URDF gazebo tags).
inline constexpr double kHuskyMu = 1.0;

/// Paper 2's payload: a UR10 (CB3) arm on a mount plate on the Husky's top.
/// Arm 32.7 kg: the sum of the link masses in Universal Robots'
/// ur_description physical_parameters.yaml (base 4.0, shoulder 7.778, upper
/// arm 12.93, forearm 3.87, wrists 1.96, 1.96, 0.202 kg; 28.7 kg without
/// the base link). Mount plate 5 kg: ASSUMPTION (a 10 mm aluminium plate of
/// about 0.45 x 0.4 m with its bolts). Centre of mass 0.61 m above the floor
/// on the robot's centre line: ASSUMPTION (the arm folded for transport over
/// the centre of the top plate, at the body's top, 0.1323 + 0.2475 =
/// 0.38 m; the folded arm's centre of mass about 0.26 m above its base,
/// the plate's 5 mm above the top). Box 0.6 x 0.3 x 0.55 m about it:
/// ASSUMPTION, the folded arm's envelope (top at 0.885 m).
inline constexpr double kUr10MassKg = 32.7;
inline constexpr double kMountPlateMassKg = 5.0;
inline constexpr double kArmPayloadMassKg = kUr10MassKg + kMountPlateMassKg;
inline constexpr double kArmPayloadComM[3] = {0.0, 0.0, 0.61};
inline constexpr double kArmPayloadBoxM[3] = {0.6, 0.3, 0.55};

inline void Set(cosim::Unit& u, const std::string& name, const cosim::Value& v) {
  u.variables().SetValue(*u.variables().Find(name), v);
}

/// A tread type (models/robots/*.yaml treads, with their sources there):
/// slip stiffnesses per unit load, relaxation lengths, damping ratio, patch.
struct TreadValues {
  double slip_stiffness, cornering_stiffness, relaxation_m, damping_ratio, patch_length_m,
      patch_width_m;
};
/// The Rob@Work 3's 160 mm polyurethane tread (raw3.yaml pu_160).
inline constexpr TreadValues kRaw3Tread = {9.5, 9.5, 0.0069, 0.1, 0.014, 0.05};
/// The Husky's 13 in pneumatic tyre (husky.yaml pneumatic_13in).
inline constexpr TreadValues kHuskyTread = {6.9, 6.9, 0.041, 0.1, 0.081, 0.1143};

/// Every wheel of `u` (n wheels) on tread `t`.
inline void SetTreads(cosim::Unit& u, std::size_t n, const TreadValues& t) {
  const auto all = [n](double v) { return std::vector<double>(n, v); };
  Set(u, "tread_slip_stiffness", all(t.slip_stiffness));
  Set(u, "tread_cornering_stiffness", all(t.cornering_stiffness));
  Set(u, "tread_longitudinal_relaxation", all(t.relaxation_m));
  Set(u, "tread_lateral_relaxation", all(t.relaxation_m));
  Set(u, "tread_damping_ratio", all(t.damping_ratio));
  Set(u, "tread_patch_length", all(t.patch_length_m));
  Set(u, "tread_patch_width", all(t.patch_width_m));
}

/// Rob@Work 3: four modules, each its own steering and drive motor.
inline std::unique_ptr<ChassisUnit> Raw3(models::Scene scene = models::OpenFloor(),
                                         const std::string& name = "robot") {
  auto u = std::make_unique<ChassisUnit>(name, std::vector<int>{0, 1, 2, 3},
                                         std::vector<int>{0, 1, 2, 3}, std::move(scene));
  Set(*u, "body_length", kRaw3BodyM[0]);
  Set(*u, "body_width", kRaw3BodyM[1]);
  Set(*u, "body_height", kRaw3BodyM[2]);
  Set(*u, "body_bottom", kRaw3BodyBottomM);
  Set(*u, "mass", kRaw3MassKg);
  Set(*u, "module_mass", kRaw3ModuleMassKg);
  Set(*u, "com_height", kRaw3ComHeightM);
  Set(*u, "wheel_radius", kRaw3WheelRadiusM);
  Set(*u, "wheel_x", std::vector<double>(kRaw3WheelXM, kRaw3WheelXM + 4));
  Set(*u, "wheel_y", std::vector<double>(kRaw3WheelYM, kRaw3WheelYM + 4));
  Set(*u, "steer_rotor_inertia", kRaw3SteerRotorKgm2);
  Set(*u, "drive_rotor_inertia", kRaw3DriveRotorKgm2);
  SetTreads(*u, 4, kRaw3Tread);
  return u;
}

/// Husky A200: four fixed wheels, order front-left, rear-left, front-right,
/// rear-right; the left pair on drive motor 0, the right pair on 1.
/// `moving_boxes` and `moving_cylinders` add those inputs (other robots,
/// workers).
inline std::unique_ptr<ChassisUnit> Husky(models::Scene scene, const std::string& name = "husky",
                                          int moving_boxes = 0, int moving_cylinders = 0) {
  auto u = std::make_unique<ChassisUnit>(name, std::vector<int>{-1, -1, -1, -1},
                                         std::vector<int>{0, 0, 1, 1}, std::move(scene),
                                         moving_boxes, moving_cylinders);
  const double a = kHuskyHalfBaseM, b = kHuskyHalfTrackM;
  Set(*u, "body_length", kHuskyBodyM[0]);
  Set(*u, "body_width", kHuskyBodyM[1]);
  Set(*u, "body_height", kHuskyBodyM[2]);
  Set(*u, "body_bottom", kHuskyBodyBottomM);
  Set(*u, "mass", kHuskyMassKg);
  Set(*u, "module_mass", kHuskyWheelMassKg);
  Set(*u, "com_height", kHuskyComHeightM);
  Set(*u, "wheel_radius", kHuskyWheelRadiusM);
  Set(*u, "wheel_x", std::vector<double>{a, -a, a, -a});
  Set(*u, "wheel_y", std::vector<double>{b, b, -b, -b});
  // The gear-motor rotor is not published (ratio "about 79:1, not
  // confirmed"): the tests leave it out; none of their steady states
  // depends on an inertia.
  Set(*u, "drive_rotor_inertia", 0.0);
  SetTreads(*u, 4, kHuskyTread);
  return u;
}

/// The Husky with paper 2's arm payload (UR10 and mount plate).
inline std::unique_ptr<ChassisUnit> HuskyWithArm(models::Scene scene,
                                                 const std::string& name = "husky") {
  auto u = Husky(std::move(scene), name);
  Set(*u, "payload_mass", kArmPayloadMassKg);
  Set(*u, "payload_position", std::vector<double>(kArmPayloadComM, kArmPayloadComM + 3));
  Set(*u, "payload_size", std::vector<double>(kArmPayloadBoxM, kArmPayloadBoxM + 3));
  return u;
}

/// An open floor of friction `mu` with no belts.
inline models::Scene Floor(double mu) {
  models::Scene s = models::OpenFloor();
  s.surfaces[0].friction = mu;
  return s;
}

/// An open floor (friction mu) with one belt `area` whose top has friction
/// mu too (0.8: the chassis tests' wheel friction, polyurethane tread on
/// sealed concrete as in models/scenes/factory_line.yaml).
inline models::Scene OneBelt(const models::Rect& area, double mu = 0.8) {
  models::Scene s = Floor(mu);
  s.surfaces.push_back({"belt", mu, 0.2, 500.0});
  models::Belt belt;
  belt.name = "belt";
  belt.area = area;
  belt.surface = 1;
  s.belts.push_back(belt);
  return s;
}

}  // namespace linesim::chassis::test_robots
