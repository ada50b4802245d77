#pragma once

#include <array>

/// Fraunhofer IPA Rob@Work 3, the robot of paper 1: the numbers the units'
/// defaults are built from, kept once here (the YAML model files in
/// models/chassis and models/motors repeat them for scenarios).
namespace linesim::models::raw3 {

/// Total mass (paper 1, Table I).
inline constexpr double kMassKg = 120.0;
/// Wheel radius (raw3-1 Platform.ini, FACTS.md).
inline constexpr double kWheelRadiusM = 0.080;
/// Steering-axis positions of modules W1..W4 in base_link (raw3-1
/// Platform.ini, FACTS.md).
inline constexpr std::array<double, 4> kWheelXM = {0.368, -0.368, -0.368, 0.368};
inline constexpr std::array<double, 4> kWheelYM = {0.186, 0.134, -0.186, -0.134};

/// Drive gear and steer belt ratios (FACTS.md). The efficiencies are
/// ASSUMPTIONS (a two-stage planetary gearhead, a toothed belt), not
/// measured: see models/motors/raw3_drive.yaml and raw3_steer.yaml.
inline constexpr double kDriveGearRatio = 21.0;
inline constexpr double kDriveGearEfficiency = 0.75;
inline constexpr double kSteerGearRatio = 4.0;
inline constexpr double kSteerGearEfficiency = 0.9;

}  // namespace linesim::models::raw3
