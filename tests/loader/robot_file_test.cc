#include "loader/robot_file.h"

#include <gtest/gtest.h>

#include <string>

#include "scenario_test.h"

namespace linesim::loader {
namespace {

using testing::Has;
using testing::WriteScenario;

// Reads a robot file, as a robot scenario in the same folder names it.
struct Read {
  std::optional<RobotFile> file;
  std::string issues;
};

Read ReadModel(const std::string& model, const std::string& relative_to = "scenario.yaml") {
  YamlReader r(relative_to);
  Read out;
  out.file = ReadRobotFile(r, YAML::Node(), "robot.model", model, relative_to);
  for (const auto& issue : r.issues()) out.issues += issue.ToString() + "\n";
  return out;
}

// A complete differential robot with one line left out or changed by the
// test, to check what is refused and where.
const char* kBody =
    "{length_m: 1, width_m: 0.6, bottom_m: 0.1, height_m: 0.3, mass_kg: 40, com_height_m: 0.2}";

// A wheel without a `tread` key gets the file's one tread type (the treads
// come last, so that the lines the tests name stay where they were).
std::string Robot(std::string wheel0, const std::string& body = kBody) {
  if (wheel0.find("tread:") == std::string::npos && !wheel0.empty() && wheel0.back() == '}') {
    wheel0.insert(wheel0.size() - 1, ", tread: t");
  }
  return "body: " + body + "\n" +
         "wheels:\n"
         "  - " + wheel0 + "\n"
         "  - {name: r, x_m: 0, y_m: -0.3, radius_m: 0.1, width_m: 0.05, mass_kg: 2, "
         "drive_motor: right, tread: t}\n"
         "motor_groups:\n"
         "  - {name: drive, model: maxon_re40_148877, gear_ratio: 20, gear_efficiency: 0.8,\n"
         "     motors: [left, right]}\n"
         "controller: {kind: differential, effective_track: 0.8}\n"
         "path_follower: {max_speed: 1.0, max_yaw_rate: 1.0}\n"
         "treads:\n"
         "  t: {material: rubber, slip_stiffness: 6.9, cornering_stiffness: 6.9,\n"
         "      longitudinal_relaxation_m: 0.04, lateral_relaxation_m: 0.04, damping_ratio: 0.1,\n"
         "      patch_length_m: 0.08, patch_width_m: 0.05}\n";
}

const char* kLeft =
    "{name: l, x_m: 0, y_m: 0.3, radius_m: 0.1, width_m: 0.05, mass_kg: 2, drive_motor: left}";

// Guards the shipped descriptions: both robots of the papers read, with the
// numbers of their sources (paper 1 Table I and the raw3-1 Platform.ini; the
// Husky URDF and manual) and the motor groups' gears.
TEST(RobotFile, ShippedRobotsRead) {
  const Read raw3 = ReadModel("raw3");
  ASSERT_TRUE(raw3.file) << raw3.issues;
  const models::RobotDescription& r = raw3.file->robot;
  EXPECT_EQ(r.controller, models::ControllerKind::kSwerve);
  ASSERT_EQ(r.wheels.size(), 4u);
  EXPECT_EQ(r.wheels[1].x_m, -0.368);
  EXPECT_EQ(r.wheels[1].y_m, 0.134);
  EXPECT_EQ(r.body.mass_kg, 120.0);
  // The box from the URDF's underside (0.07 m) to Table I's 0.40 m top; the
  // centre of mass where the file assumes it, low in the box.
  EXPECT_EQ(r.body.bottom_m, 0.07);
  EXPECT_NEAR(r.body.top_m(), 0.40, 1e-15);
  EXPECT_EQ(r.body.com_height_m, 0.13);
  ASSERT_EQ(r.Motors().size(), 8u);
  EXPECT_EQ(r.motor_groups[1].gear_ratio, 21.0);
  EXPECT_EQ(r.motor_groups[1].motor.at("gear_ratio"), 21.0);
  EXPECT_EQ(r.motor_groups[1].motor.at("torque_constant"), 0.0302);  // maxon RE 40 sheet
  // 4 PX4Flow, 2 S300, an IMU, the joint encoders.
  ASSERT_EQ(r.sensor_mounts.size(), 8u);
  EXPECT_EQ(r.sensor_mounts[4].model, "sick_s300");
  EXPECT_EQ(r.sensor_mounts[7].kind, "wheel_encoder");

  const Read husky = ReadModel("husky");
  ASSERT_TRUE(husky.file) << husky.issues;
  const models::RobotDescription& h = husky.file->robot;
  EXPECT_EQ(h.controller, models::ControllerKind::kDifferential);
  ASSERT_EQ(h.wheels.size(), 4u);
  EXPECT_FALSE(h.wheels[0].steer_motor);
  EXPECT_EQ(h.wheels[0].drive_motor, h.wheels[1].drive_motor);  // belt-coupled side
  EXPECT_EQ(h.wheels[0].radius_m, 0.1651);
  // The URDF's base box over its bottom plate: 0.1323 to 0.3798 m.
  EXPECT_EQ(h.body.bottom_m, 0.1323);
  EXPECT_NEAR(h.body.top_m(), 0.3798, 1e-15);
  EXPECT_EQ(h.Motors().size(), 2u);
  ASSERT_EQ(h.sensor_mounts.size(), 3u);
  EXPECT_EQ(h.sensor_mounts[0].model, "sick_lms151");
}

// Guards "no silent default": a description that leaves out a required
// value is refused naming the file, the line of the item and the key.
TEST(RobotFile, MissingRequiredValueNamesFileLineAndKey) {
  const std::string file = WriteScenario(
      "robot_missing.yaml",
      Robot("{name: l, x_m: 0, y_m: 0.3, width_m: 0.05, mass_kg: 2, drive_motor: left}"));
  const Read read = ReadModel(file);
  EXPECT_FALSE(read.file);
  EXPECT_TRUE(Has(read.issues, file + ":3")) << read.issues;
  EXPECT_TRUE(Has(read.issues, "wheels.0.radius_m")) << read.issues;
  EXPECT_TRUE(Has(read.issues, "missing required key")) << read.issues;
}

// Guards the body's keys (issue 35: the box's heights are a fact of their
// own, not derived from the centre of mass): a missing bottom_m, an
// underside below the floor, a centre of mass outside the box and an
// unknown key are each refused in the file, on the body's line (1), at
// the key path, saying what was expected.
TEST(RobotFile, BodyKeysAreCheckedWhereWritten) {
  const auto issues = [](const std::string& name, const std::string& body) {
    const std::string file = WriteScenario(name, Robot(kLeft, body));
    const Read read = ReadModel(file);
    EXPECT_FALSE(read.file) << body;
    return std::pair{file, read.issues};
  };
  {
    const auto [file, text] =
        issues("robot_no_bottom.yaml",
               "{length_m: 1, width_m: 0.6, height_m: 0.3, mass_kg: 40, com_height_m: 0.2}");
    EXPECT_TRUE(Has(text, file + ":1: body.bottom_m: missing required key")) << text;
  }
  {
    const auto [file, text] =
        issues("robot_sunk_body.yaml",
               "{length_m: 1, width_m: 0.6, bottom_m: -0.05, height_m: 0.3, mass_kg: 40, "
               "com_height_m: 0.2}");
    EXPECT_TRUE(Has(text, file + ":1: body.bottom_m: value -0.05 is out of range: expected a "
                                 "number >= 0 and <= 10"))
        << text;
  }
  {
    const auto [file, text] =
        issues("robot_mass_outside.yaml",
               "{length_m: 1, width_m: 0.6, bottom_m: 0.25, height_m: 0.3, mass_kg: 40, "
               "com_height_m: 0.2}");
    EXPECT_TRUE(Has(text, file + ":1: body.com_height_m: the body's centre of mass must lie "
                                 "within its box, from bottom_m 0.25 m to bottom_m + height_m "
                                 "0.55 m above the floor; got 0.2 m"))
        << text;
  }
  {
    const auto [file, text] =
        issues("robot_clearance_key.yaml",
               "{length_m: 1, width_m: 0.6, bottom_m: 0.1, ground_clearance_m: 0.1, height_m: 0.3, "
               "mass_kg: 40, com_height_m: 0.2}");
    EXPECT_TRUE(Has(text, "body.ground_clearance_m: unknown key")) << text;
  }
  // The box and the centre of mass apart, the mass at the box's bottom:
  // accepted, each value as written.
  const Read ok = ReadModel(
      WriteScenario("robot_low_mass.yaml",
                    Robot(kLeft,
                          "{length_m: 1, width_m: 0.6, bottom_m: 0.2, height_m: 0.3, mass_kg: 40, "
                          "com_height_m: 0.2}")));
  ASSERT_TRUE(ok.file) << ok.issues;
  EXPECT_EQ(ok.file->robot.body.bottom_m, 0.2);
  EXPECT_EQ(ok.file->robot.body.height_m, 0.3);
  EXPECT_EQ(ok.file->robot.body.com_height_m, 0.2);
}

// Guards issue 24 (item 5): two wheels with one name were accepted (the
// columns, plots and messages that name a wheel would mix them): refused
// at the second one's name, in the file, with its line (the Robot() text's
// line 4).
TEST(RobotFile, TwoWheelsWithOneNameAreRefused) {
  const std::string file = WriteScenario(
      "robot_twin_wheels.yaml",
      Robot("{name: r, x_m: 0, y_m: 0.3, radius_m: 0.1, width_m: 0.05, mass_kg: 2, "
            "drive_motor: left}"));
  const Read read = ReadModel(file);
  EXPECT_FALSE(read.file);
  EXPECT_TRUE(Has(read.issues, file + ":4: wheels.1.name: wheel 'r' is named twice")) << read.issues;
}

// Guards the topology checks: a wheel naming no motor of the groups, a
// motor that moves nothing, a differential base with a steered wheel, and
// an unknown key in the file.
TEST(RobotFile, TopologyProblemsAreNamed) {
  const std::string unknown_motor = WriteScenario(
      "robot_unknown_motor.yaml",
      Robot("{name: l, x_m: 0, y_m: 0.3, radius_m: 0.1, width_m: 0.05, mass_kg: 2, "
            "drive_motor: lft}"));
  const Read a = ReadModel(unknown_motor);
  EXPECT_TRUE(Has(a.issues, "wheels.0.drive_motor: no motor 'lft' in motor_groups")) << a.issues;
  EXPECT_TRUE(Has(a.issues, "motor 'left' moves no wheel")) << a.issues;

  const std::string steered = WriteScenario(
      "robot_steered.yaml",
      Robot("{name: l, x_m: 0, y_m: 0.3, radius_m: 0.1, width_m: 0.05, mass_kg: 2, "
            "steer_inertia_kgm2: 0.01, steer_motor: right, drive_motor: left}"));
  EXPECT_TRUE(Has(ReadModel(steered).issues, "a differential base has no steered wheel"))
      << ReadModel(steered).issues;

  const std::string typo = WriteScenario("robot_typo.yaml", Robot(kLeft) + "wheel: []\n");
  EXPECT_TRUE(Has(ReadModel(typo).issues, "wheel: unknown key; closest: wheels"))
      << ReadModel(typo).issues;
  EXPECT_FALSE(ReadModel(typo).file);

  EXPECT_TRUE(ReadModel(WriteScenario("robot_ok.yaml", Robot(kLeft))).file);
}

// Guards the treads (the tyre model's parameters, every one with a source
// in the shipped files): a wheel naming no known tread type, a tread type
// missing a key, and a file without treads are each named at their key.
TEST(RobotFile, TreadsAreRequiredAndNamedAtTheirKeys) {
  const Read unknown = ReadModel(
      WriteScenario("robot_unknown_tread.yaml",
                    Robot("{name: l, x_m: 0, y_m: 0.3, radius_m: 0.1, width_m: 0.05, mass_kg: 2, "
                          "drive_motor: left, tread: slick}")));
  EXPECT_FALSE(unknown.file);
  EXPECT_TRUE(Has(unknown.issues, "wheels.0.tread: no tread 'slick' in treads; treads: t"))
      << unknown.issues;

  std::string text = Robot(kLeft);
  text.replace(text.find("damping_ratio: 0.1,"), 19, "");
  const Read missing = ReadModel(WriteScenario("robot_tread_missing_key.yaml", text));
  EXPECT_FALSE(missing.file);
  EXPECT_TRUE(Has(missing.issues, "treads.t.damping_ratio")) << missing.issues;

  text = Robot(kLeft);
  const auto from = text.find("treads:"), to = text.find("wheels:");
  text.erase(from, to - from);
  const Read none = ReadModel(WriteScenario("robot_no_treads.yaml", text));
  EXPECT_FALSE(none.file);
  EXPECT_TRUE(Has(none.issues, "treads: missing required key")) << none.issues;
}

// Guards the sensor mounts' keys: a PX4Flow looks straight down (a roll or
// pitch would be dropped, so it is refused), a wheel encoder has no pose,
// and a step below 1 ns (which would round to "the default") is refused.
TEST(RobotFile, SensorMountsTakeOnlyWhatTheirKindUses) {
  const std::string pitched = WriteScenario(
      "robot_pitched_flow.yaml",
      Robot(kLeft) + "sensor_mounts:\n  - {name: f, kind: px4flow, x_m: 0.4, y_m: 0.2, "
                     "z_m: 0.18, pitch_deg: 90}\n");
  const Read a = ReadModel(pitched);
  EXPECT_TRUE(Has(a.issues, "sensor_mounts.0.pitch_deg: unknown key")) << a.issues;

  const std::string posed = WriteScenario(
      "robot_posed_encoder.yaml",
      Robot(kLeft) + "sensor_mounts:\n  - {name: e, kind: wheel_encoder, x_m: 0.1}\n");
  EXPECT_TRUE(Has(ReadModel(posed).issues, "sensor_mounts.0.x_m: unknown key"))
      << ReadModel(posed).issues;

  const std::string tiny = WriteScenario(
      "robot_tiny_step.yaml",
      Robot(kLeft) + "sensor_mounts:\n  - {name: i, kind: imu, x_m: 0, y_m: 0, z_m: 0.2, "
                     "step_s: 1.0e-10}\n");
  EXPECT_TRUE(Has(ReadModel(tiny).issues, "sensor_mounts.0.step_s")) << ReadModel(tiny).issues;
}

// Guards what the chassis and the one motor unit need to be consistent:
// wheels of one mass (the chassis lumps one module mass into each), and
// motor models that give the same keys (element arrays of one dc_motor
// unit). Each is named at its key in the robot file.
TEST(RobotFile, WheelMassesAndMotorModelsMustAgree) {
  std::string text = Robot(kLeft);
  text.replace(text.find("mass_kg: 2, drive_motor: right"), 9, "mass_kg: 3");
  const std::string f = WriteScenario("robot_heavy.yaml", text);
  const Read a = ReadModel(f);
  EXPECT_FALSE(a.file);
  EXPECT_TRUE(Has(a.issues, "wheels.1.mass_kg: every wheel must have the mass of the first"))
      << a.issues;

  const std::string motor = WriteScenario("bare_motor.yaml", "resistance: 0.3\n"
                                                             "inductance: 1.0e-4\n"
                                                             "torque_constant: 0.03\n"
                                                             "rotor_inertia: 1.0e-5\n");
  std::string two = Robot(kLeft);
  two.replace(two.find("  - {name: drive, model: maxon_re40_148877,"), 0,
              "  - {name: other, model: " + motor + ", gear_ratio: 10, gear_efficiency: 0.9,\n"
              "     motors: [spare]}\n");
  two.replace(two.find("drive_motor: right, tread: t}"), 29,
              "drive_motor: right, tread: t}\n  - {name: s, x_m: 0.2, y_m: 0.3, radius_m: 0.1, "
              "width_m: 0.05, mass_kg: 2, drive_motor: spare, tread: t}");
  const Read b = ReadModel(WriteScenario("robot_two_motors.yaml", two));
  EXPECT_TRUE(Has(b.issues, "motor_groups.1.model: the motor models of one robot must set the "
                            "same keys: 'viscous_friction'"))
      << b.issues;
}

// Guards the name: an unknown robot lists the shipped ones.
TEST(RobotFile, UnknownRobotNamesTheClosest) {
  const Read read = ReadModel("huskey");
  EXPECT_FALSE(read.file);
  EXPECT_TRUE(Has(read.issues, "husky")) << read.issues;
}

}  // namespace
}  // namespace linesim::loader
