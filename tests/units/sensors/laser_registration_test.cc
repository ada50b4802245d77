// The laser_scanner factory (units/sensors/laser_registration.cc): its
// structural keys from the parameters or the model file.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "config/unit_registry.h"
#include "config/yaml_reader.h"

namespace linesim::sensors {
namespace {

struct Built {
  std::unique_ptr<cosim::Unit> unit;
  std::vector<config::Issue> issues;
};

Built Make(const std::string& parameters, const YAML::Node& model, const std::string& model_file) {
  const config::UnitType* type = config::FindUnitType("laser_scanner");
  EXPECT_NE(type, nullptr);
  if (!type) return {};
  config::YamlReader reader("scenario.yaml");
  const YAML::Node params = YAML::Load(parameters);
  const std::string name = "laser", path = "units.laser.parameters";
  const models::Scene scene = models::OpenFloor();
  auto unit = type->create({name, 1, reader, params, path, scene, model, model_file});
  return {std::move(unit), reader.issues()};
}

const std::string kS300 = std::string(LINESIM_SOURCE_DIR) + "/models/sensors/sick_s300.yaml";

// Guards against structural keys not read from the model file (the beam
// count shapes `ranges`; the S300's field adds field_clear), or the
// parameters not taking precedence.
TEST(LaserScannerFactory, ReadsStructuralKeysFromTheModelFile) {
  const YAML::Node model = YAML::LoadFile(kS300);
  Built b = Make("{model: sick_s300}", model, kS300);
  ASSERT_TRUE(b.unit) << (b.issues.empty() ? "" : b.issues[0].message);
  const auto ranges = b.unit->variables().Find("ranges");
  ASSERT_TRUE(ranges);
  EXPECT_EQ(b.unit->variables().info(*ranges).size, 541u);
  EXPECT_TRUE(b.unit->variables().Find("field_clear"));

  Built c = Make("{model: sick_s300, beam_count: 271, protective_field: [[0, 0], [1, 0], [0, 1]]}",
                 model, kS300);
  ASSERT_TRUE(c.unit);
  EXPECT_EQ(c.unit->variables().info(*c.unit->variables().Find("ranges")).size, 271u);
}

// Guards against bad structural keys accepted or reported in the wrong
// file: a missing beam_count is reported (no model gives it), a bad one in
// the model file at that file, a two-corner field at its key.
TEST(LaserScannerFactory, ReportsBadStructuralKeys) {
  Built a = Make("{mount_x: 0.1}", YAML::Node(), "");
  EXPECT_FALSE(a.unit);
  ASSERT_EQ(a.issues.size(), 1u);
  EXPECT_EQ(a.issues[0].key_path, "units.laser.parameters.beam_count");

  YAML::Node model = YAML::LoadFile(kS300);
  model["beam_count"] = 0;
  Built b = Make("{model: sick_s300}", model, kS300);
  EXPECT_FALSE(b.unit);
  ASSERT_EQ(b.issues.size(), 1u);
  EXPECT_EQ(b.issues[0].file, kS300);
  EXPECT_EQ(b.issues[0].key_path, "beam_count");

  Built c = Make("{beam_count: 10, protective_field: [[0, 0], [1, 0]]}", YAML::Node(), "");
  EXPECT_FALSE(c.unit);
  ASSERT_EQ(c.issues.size(), 1u);
  EXPECT_EQ(c.issues[0].key_path, "units.laser.parameters.protective_field");
}

}  // namespace
}  // namespace linesim::sensors
