#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>

#include "loader/scenario.h"
#include "scenario_test.h"

// The sensors concern (loader/assembly/sensors.cc): a unit per sensor mount
// of the robot description, configured by the scenario's sensors: section.
namespace linesim::loader {
namespace {

using testing::Has;
using testing::Param;
using testing::Issues;
using testing::WriteScenario;

const std::string kCross = LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml";
const std::string kHusky = LINESIM_SOURCE_DIR "/scenarios/husky_floor_path.yaml";

const cosim::VariableTable& Table(const Scenario& s, const std::string& unit) {
  return s.system->unit(*s.system->FindUnit(unit)).variables();
}


bool Connected(const Scenario& s, const std::string& from, const std::string& to) {
  for (const auto& c : s.system->connections()) {
    if (c.from.ToString() == from && c.to.ToString() == to) return true;
  }
  return false;
}

// The scenario file with its sensors: section replaced by `sensors`.
std::string WithSensors(const std::string& file, const std::string& name,
                        const std::string& sensors) {
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find("sensors:\n  default: true\n");
  text.replace(at, std::string("sensors:\n  default: true\n").size(), sensors);
  // The scene and robot models are found from the temporary folder by path.
  const auto scene = text.find("model: factory_line");
  if (scene != std::string::npos) {
    text.replace(scene, std::string("model: factory_line").size(),
                 "model: " LINESIM_SOURCE_DIR "/models/scenes/factory_line.yaml");
  }
  return WriteScenario(name, text);
}

// Guards the defaults: every mount of the Rob@Work 3 description becomes a
// unit of its kind with the mount's pose and device model (raw3-1
// calibration: front S300 at (0.465, -0.232, 0.178) m, yaw -45 deg), wired
// to the chassis's ground truth and the belt; the encoders read the eight
// joints at the 20 ms control period; the belt's ground truth and the
// evaluation units come with them.
TEST(SensorsAssembly, EveryMountOfTheRobotIsAUnit) {
  const Scenario s = LoadScenario(kCross);
  for (const char* unit : {"flow_front_left", "flow_rear_left", "flow_rear_right",
                           "flow_front_right", "laser_front", "laser_rear", "imu",
                           "wheel_encoders", "belt_ground_truth", "clearance", "flow_error"}) {
    EXPECT_TRUE(s.system->FindUnit(unit)) << unit;
  }
  EXPECT_EQ(s.system->unit(*s.system->FindUnit("laser_front")).type_name(), "laser_scanner");
  EXPECT_EQ(Param(s, "laser_front", "mount_x"), 0.465);
  EXPECT_EQ(Param(s, "laser_front", "mount_y"), -0.232);
  EXPECT_EQ(Param(s, "laser_front", "mount_z"), 0.178);
  EXPECT_NEAR(Param(s, "laser_front", "mount_yaw"), -std::numbers::pi / 4, 1e-15);
  // From models/sensors/sick_s300.yaml: 541 beams, 40 ms, 1 cm.
  EXPECT_EQ(Table(s, "laser_front").info(*Table(s, "laser_front").Find("ranges")).size, 541u);
  EXPECT_EQ(Param(s, "laser_front", "scan_period"), 0.04);
  EXPECT_EQ(Param(s, "laser_front", "range_resolution"), 0.01);
  // models/robots/raw3.yaml: 0.1841 m (the authors' public code), its
  // added light 500 lx (an assumption stated there).
  EXPECT_EQ(Param(s, "flow_front_left", "mount_height"), 0.1841);
  EXPECT_EQ(Param(s, "flow_front_left", "added_light"), 500.0);
  EXPECT_TRUE(Connected(s, "chassis.position_3d", "laser_front.position_3d"));
  EXPECT_TRUE(Connected(s, "belt.travel", "laser_front.belt_travel"));
  EXPECT_TRUE(Connected(s, "chassis.angular_velocity", "imu.base_angular_velocity"));
  EXPECT_TRUE(Connected(s, "belt.velocity", "flow_front_left.belt_velocity"));
  EXPECT_TRUE(Connected(s, "chassis.steer_angle[0]", "wheel_encoders.angle[0]"));
  EXPECT_TRUE(Connected(s, "chassis.drive_angle[3]", "wheel_encoders.angle[7]"));
  EXPECT_TRUE(Connected(s, "belt.travel[0]", "belt_ground_truth.travel"));
  // The control period and the IMU's 100 Hz, in master steps.
  const auto step = s.master->options().base_step;
  EXPECT_EQ(s.master->decimation(*s.system->FindUnit("wheel_encoders")), 20'000'000 / step);
  EXPECT_EQ(s.master->decimation(*s.system->FindUnit("imu")), 10'000'000 / step);
  EXPECT_EQ(s.master->decimation(*s.system->FindUnit("laser_front")), 1);
  // 4096 counts per motor turn x drive gear 21 (raw3.yaml).
  EXPECT_EQ(Param(s, "wheel_encoders", "counts_per_revolution", 4), 4096.0 * 21);
  // The clearance body is the chassis's box: where raw3.yaml's bottom_m
  // puts it, not about the centre of mass.
  EXPECT_EQ(Param(s, "clearance", "body_bottom"), 0.07);
  EXPECT_EQ(Param(s, "clearance", "body_height"), 0.33);
  EXPECT_EQ(Param(s, "chassis", "body_bottom"), 0.07);
  EXPECT_EQ(Param(s, "chassis", "com_height"), 0.13);
}

// Guards the Husky's: an LMS151 (its own model file: 0.5 deg at 50 Hz, one
// of the two settings paper 2 names), two encoder channels
// on the two drive motors at 78,000 ticks per metre (Husky manual) on
// 0.1651 m wheels.
TEST(SensorsAssembly, HuskyMountsItsOwnDevices) {
  const Scenario s = LoadScenario(kHusky);
  EXPECT_EQ(Table(s, "laser_front").info(*Table(s, "laser_front").Find("ranges")).size, 541u);
  EXPECT_EQ(Param(s, "laser_front", "scan_period"), 0.02);
  EXPECT_EQ(Param(s, "laser_front", "noise_sigma"), 0.012);
  EXPECT_EQ(Param(s, "wheel_encoders", "counts_per_revolution", 1), 80913.6);
  EXPECT_TRUE(Connected(s, "chassis.drive_angle[1]", "wheel_encoders.angle[1]"));
  EXPECT_FALSE(s.system->FindUnit("flow_front_left"));
}

// Guards the section: default off with one sensor on, a sensor off, a
// device option and a step of the scenario's own.
TEST(SensorsAssembly, TheScenarioChoosesSensorsAndTheirOptions) {
  const Scenario only = LoadScenario(
      WithSensors(kCross, "only_laser.yaml", "sensors:\n  default: false\n  laser_rear: true\n"));
  EXPECT_TRUE(only.system->FindUnit("laser_rear"));
  for (const char* unit : {"laser_front", "flow_front_left", "imu", "wheel_encoders",
                           "belt_ground_truth", "flow_error"}) {
    EXPECT_FALSE(only.system->FindUnit(unit)) << unit;
  }
  EXPECT_TRUE(only.system->FindUnit("clearance"));

  const Scenario tuned = LoadScenario(WithSensors(
      kCross, "tuned.yaml",
      "sensors:\n  laser_rear: false\n  laser_front: {step_s: 0.01, parameters: "
      "{noise_sigma: 0.03}}\n"));
  EXPECT_FALSE(tuned.system->FindUnit("laser_rear"));
  EXPECT_EQ(Param(tuned, "laser_front", "noise_sigma"), 0.03);
  EXPECT_EQ(tuned.master->decimation(*tuned.system->FindUnit("laser_front")),
            10'000'000 / tuned.master->options().base_step);
}

// Guards the errors: an unknown sensor name (with the closest), a value the
// assembly derives from the mount, a device option the unit refuses (at the
// scenario's key), all with file and key.
TEST(SensorsAssembly, BadEntriesAreReportedAtTheirKeys) {
  const std::string typo = WithSensors(kCross, "typo.yaml", "sensors:\n  laser_fornt: false\n");
  const std::string a = Issues(typo);
  EXPECT_TRUE(Has(a, typo + ":")) << a;
  EXPECT_TRUE(Has(a, "sensors.laser_fornt: unknown key; closest: sensors.laser_front")) << a;

  const std::string derived = WithSensors(
      kCross, "derived.yaml", "sensors:\n  laser_front: {parameters: {mount_x: 1.0}}\n");
  const std::string b = Issues(derived);
  EXPECT_TRUE(Has(b, "sensors.laser_front.parameters.mount_x: the assembly derives")) << b;

  // A sensor turned off is still checked: its typo is reported.
  const std::string off = WithSensors(
      kCross, "off_typo.yaml", "sensors:\n  laser_front: {enabled: false, stepp_s: 0.002}\n");
  const std::string d = Issues(off);
  EXPECT_TRUE(Has(d, "sensors.laser_front.stepp_s: unknown key; closest: sensors.laser_front.step_s"))
      << d;

  const std::string bad = WithSensors(
      kCross, "bad_value.yaml", "sensors:\n  laser_front: {parameters: {noise_sigma: -1}}\n");
  const std::string c = Issues(bad);
  EXPECT_TRUE(Has(c, bad + ":")) << c;
  EXPECT_TRUE(Has(c, "sensors.laser_front.parameters.noise_sigma")) << c;
}

}  // namespace
}  // namespace linesim::loader
