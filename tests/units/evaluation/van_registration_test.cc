// The factories of the van bay's ground truth (units/evaluation/
// van_registration.cc): beacons from the scene, beam_count structural.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "config/unit_registry.h"
#include "config/yaml_reader.h"

namespace linesim::evaluation {
namespace {

struct Built {
  std::unique_ptr<cosim::Unit> unit;
  std::vector<config::Issue> issues;
};

Built Make(const std::string& type_name, const char* parameters, const models::Scene& scene) {
  const config::UnitType* type = config::FindUnitType(type_name);
  EXPECT_NE(type, nullptr) << type_name;
  if (!type) return {};
  config::YamlReader reader("scenario.yaml");
  const YAML::Node params = parameters ? YAML::Load(parameters) : YAML::Node();
  const std::string name = "beacons", path = "units.beacons.parameters";
  const YAML::Node model;
  const std::string model_file;
  auto unit = type->create({name, 1, reader, params, path, scene, model, model_file});
  return {std::move(unit), reader.issues()};
}

models::Scene WithBeacons(int cylinders, bool box) {
  models::Scene s = models::OpenFloor();
  s.obstacles.push_back({"wall", "wall", models::BoxSolid(8.0, 0.0, 0.0, 0.1, 4.0, 2.0)});
  for (int i = 0; i < cylinders; ++i) {
    s.obstacles.push_back(
        {"b" + std::to_string(i), "beacon", models::CylinderSolid(6.0 + i, 0.75, 0.04, 0.8)});
  }
  if (box) s.obstacles.push_back({"bb", "beacon", models::BoxSolid(6.0, -0.75, 0, 0.1, 0.1, 1)});
  return s;
}

// Guards the beacons taken from the scene (kind beacon only) and the beam
// count shaping `ranges`.
TEST(VanFactories, BeaconLocalizationFromTheScene) {
  Built b = Make("beacon_localization", "{beam_count: 541}", WithBeacons(4, false));
  ASSERT_TRUE(b.unit) << (b.issues.empty() ? "" : b.issues[0].message);
  EXPECT_EQ(b.unit->variables().info(*b.unit->variables().Find("ranges")).size, 541u);
  EXPECT_TRUE(b.unit->CheckParameters().size() > 0);  // the mount is robot-specific
  // `inspect`: no parameters, a scene without beacons.
  Built i = Make("beacon_localization", nullptr, models::OpenFloor());
  EXPECT_TRUE(i.unit);
  Built f = Make("final_pose_error", nullptr, models::OpenFloor());
  EXPECT_TRUE(f.unit);
}

// Guards the factory's refusals: fewer than 3 beacons, a beacon that is no
// cylinder, no beam_count.
TEST(VanFactories, RefusesTooFewOrNonCylinderBeaconsAndNoBeamCount) {
  Built two = Make("beacon_localization", "{beam_count: 541}", WithBeacons(2, false));
  EXPECT_FALSE(two.unit);
  ASSERT_EQ(two.issues.size(), 1u);
  EXPECT_NE(two.issues[0].message.find("at least 3"), std::string::npos) << two.issues[0].message;
  Built box = Make("beacon_localization", "{beam_count: 541}", WithBeacons(3, true));
  EXPECT_FALSE(box.unit);
  ASSERT_EQ(box.issues.size(), 1u);
  EXPECT_NE(box.issues[0].message.find("not a cylinder"), std::string::npos);
  Built none = Make("beacon_localization", "{mount_x: 0.45}", WithBeacons(4, false));
  EXPECT_FALSE(none.unit);
  ASSERT_EQ(none.issues.size(), 1u);
  EXPECT_EQ(none.issues[0].key_path, "units.beacons.parameters.beam_count");
}

}  // namespace
}  // namespace linesim::evaluation
