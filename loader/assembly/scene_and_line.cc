#include <algorithm>

#include "loader/assembly/concerns.h"
#include "loader/scene_file.h"

namespace linesim::loader::assembly {

models::Scene AddScene(SystemBuilder& b) {
  YamlReader& r = b.reader();
  const YAML::Node root = b.root();
  const YAML::Node given = Child(root, "scene");
  const bool written = given.IsDefined() && !given.IsNull();
  if (written && !r.ExpectMap(given, "scene")) return models::OpenFloor();
  // A new map whose values are the scenario's own nodes, so that problems
  // found in them keep their lines.
  YAML::Node scene(YAML::NodeType::Map);
  if (written) {
    for (const auto& kv : given) scene[kv.first.Scalar()] = kv.second;
  }
  // line.belts: paper 1's shorthand for the scene's belts, item by item
  // (an item past the scene's list adds a belt). The scene reader checks
  // the keys; what is wrong is reported here, where the user wrote it.
  const YAML::Node line = b.Section(root, "", "line", {"belts"});
  const YAML::Node belts = Child(line, "belts");
  const bool has_belts =
      belts.IsDefined() && !belts.IsNull() && r.ExpectSequence(belts, "line.belts");
  // Item by item, an empty list would leave the scene's belts as they are:
  // refused here, and not merged (the scene would echo it at scene.belts).
  if (has_belts && belts.size() == 0) {
    r.Error(belts, "line.belts",
            "an empty list removes nothing: line.belts overrides the scene's belts item by "
            "item, which stay as they are; leave line out, or write the belts wanted");
  } else if (has_belts) {
    const YAML::Node own = Child(scene, "belts");
    YAML::Node merged(YAML::NodeType::Sequence);
    for (std::size_t i = 0; i < std::max(belts.size(), own.IsSequence() ? own.size() : 0); ++i) {
      YAML::Node item(YAML::NodeType::Map);
      if (own.IsSequence() && i < own.size() && own[i].IsMap()) {
        for (const auto& kv : own[i]) item[kv.first.Scalar()] = kv.second;
      }
      const std::string path = JoinPath("line.belts", std::to_string(i));
      if (i < belts.size() && r.ExpectMap(belts[i], path)) {
        const std::string index = "scene.belts." + std::to_string(i);
        for (const auto& kv : belts[i]) {
          const std::string key = kv.first.Scalar();
          // The line wins over the scene: a value set for the scene's belt
          // on the command line would be lost without a word.
          if (r.FromCommandLine(JoinPath(index, key))) {
            r.Error(kv.second, JoinPath(index, key),
                    "the scenario's line.belts." + std::to_string(i) + "." + key +
                        " sets this belt value and overrides the scene's: set line.belts." +
                        std::to_string(i) + "." + key + " instead");
          }
          item[key] = kv.second;
          b.Derived(JoinPath(index, key), belts[i], path, key);
        }
        b.Origin(index, {belts[i], path, ""});
      }
      merged.push_back(item);
    }
    scene["belts"] = merged;
  }
  if (scene.size() == 0) return models::OpenFloor();
  // The scene read once, here; its problems are reported at the keys the
  // user wrote.
  SystemSpec& spec = b.spec();
  spec.scene_node = scene;
  r.SetOrigins(spec.origins);
  spec.scene = ReadScenarioScene(r, scene, r.file());
  return spec.scene;
}

void AddLine(SystemBuilder& b, const models::Scene& scene, Signals& s) {
  // Over terrain (a ramp, a van floor) the height is part of the story:
  // recorded for the side view.
  s.terrain = !scene.terrain.empty();
  if (s.terrain) s.recorded.push_back(Signal(kChassis, "position_3d"));
  s.belt_count = scene.belts.size();
  if (s.belt_count == 0) return;
  // The belt unit drives every belt of the scene; it takes them from there.
  b.Unit(kBelt, "belt");
  b.Connect(Signal(kBelt, "velocity"), Signal(kChassis, "belt_velocity"));
  b.Connect(Signal(kBelt, "travel"), Signal(kChassis, "belt_travel"));
  for (const char* v : {"speed", "on", "travel"}) s.recorded.push_back(Signal(kBelt, v));
}

}  // namespace linesim::loader::assembly
