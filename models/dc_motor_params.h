#pragma once

#include <numbers>

namespace linesim::models {

/// A brushed DC motor with a gearbox, in SI units. The defaults are the
/// maxon RE 40, dia. 40 mm, graphite brushes, 150 W, order no. 148877,
/// 24 V winding (maxon catalogue data sheet), bare motor (no gearbox).
struct DcMotorParams {
  /// Terminal resistance (data sheet: 0.299 Ohm).
  double resistance_ohm = 0.299;
  /// Terminal inductance (data sheet: 0.0823 mH).
  double inductance_h = 0.0823e-3;
  /// Torque constant, equal to the back-EMF constant in V.s/rad (data sheet:
  /// 30.2 mNm/A; speed constant 317 rpm/V gives 1/33.2 = 30.1 mV.s/rad).
  double torque_constant_nm_per_a = 30.2e-3;
  /// Rotor inertia (data sheet: 142 g.cm^2).
  double rotor_inertia_kgm2 = 142e-7;
  /// Not on the data sheet: derived from the no-load point (7580 rpm at
  /// 137 mA, 24 V) as b = k_t * I0 / omega0, about 5.2e-6 N.m.s/rad.
  /// It lumps brush and bearing friction into a viscous term.
  double viscous_friction_nms_per_rad =
      torque_constant_nm_per_a * 0.137 / (7580.0 * 2.0 * std::numbers::pi / 60.0);
  /// Motor revolutions per output revolution; 1 = no gearbox.
  double gear_ratio = 1.0;
  /// Fraction of the motor torque that reaches the output (0 < eta <= 1).
  double gear_efficiency = 1.0;
  /// Inertia at the gearbox output (load side), kg.m^2.
  double load_inertia_kgm2 = 0.0;
};

}  // namespace linesim::models
