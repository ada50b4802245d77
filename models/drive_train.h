#pragma once

/// What a joint sees of a geared DC motor: the drive-train algebra the
/// chassis and the wheel controllers are parameterised with, in one place.
namespace linesim::models {

/// A motor behind a gear, as seen at the gear's output (the joint).
struct JointDrive {
  /// eta N^2 J_rotor: the rotor's inertia seen from the output. The dc_motor
  /// unit's full mode reflects a load the other way, J_eff = J_rotor +
  /// J_load / (eta N^2), which is the same balance seen from the motor.
  double reflected_inertia_kgm2 = 0.0;
  /// k_e N (= k_t N in SI units): the voltage that holds a joint rate of
  /// 1 rad/s unloaded; a controller's back-EMF feedforward.
  double back_emf_v_per_rad_s = 0.0;
  /// eta k_t N: output torque per ampere of armature current.
  double torque_per_amp_nm = 0.0;
};

/// The joint's view of a motor with rotor inertia `rotor_inertia_kgm2`,
/// torque constant `torque_constant_nm_per_a` behind a gear of ratio
/// `gear_ratio` (motor turns per output turn) and efficiency
/// `gear_efficiency`.
inline JointDrive ReflectThroughGear(double rotor_inertia_kgm2, double torque_constant_nm_per_a,
                                     double gear_ratio, double gear_efficiency) {
  JointDrive d;
  d.reflected_inertia_kgm2 = gear_efficiency * gear_ratio * gear_ratio * rotor_inertia_kgm2;
  d.back_emf_v_per_rad_s = torque_constant_nm_per_a * gear_ratio;
  d.torque_per_amp_nm = gear_efficiency * torque_constant_nm_per_a * gear_ratio;
  return d;
}

}  // namespace linesim::models
