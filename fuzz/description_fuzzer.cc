// Robot and scene descriptions: the input is read both as a robot file (as a
// robot scenario's `robot.model: PATH` names it, motor files by name from
// models/motors) and as a scene file (as `scene.model: PATH` names it).
// ReadRobotFile reports every problem through its YamlReader; LoadSceneFile
// throws config::ScenarioError; nothing else may escape.
#include <cstddef>
#include <cstdint>
#include <string>

#include "config/scenario_error.h"
#include "config/yaml_reader.h"
#include "fuzz/fuzz_support.h"
#include "loader/robot_file.h"
#include "loader/scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string dir = linesim::fuzz::TempDir();
  const std::string robot = dir + "/robot.yaml";
  const std::string scene = dir + "/scene.yaml";
  linesim::fuzz::WriteFile(robot, data, size);
  linesim::fuzz::WriteFile(scene, data, size);
  const std::string scenario = dir + "/scenario.yaml";
  linesim::config::YamlReader r(scenario);
  (void)linesim::loader::ReadRobotFile(r, YAML::Node(), "robot.model", robot, scenario);
  try {
    (void)linesim::loader::LoadSceneFile(scene);
  } catch (const linesim::config::ScenarioError&) {
  }
  return 0;
}
