#include "loader/assembly/concerns.h"
#include "loader/scene_file.h"

namespace linesim::loader::assembly {

models::Scene AddScene(SystemBuilder& b) {
  YamlReader& r = b.reader();
  const YAML::Node root = b.root();
  YAML::Node scene(YAML::NodeType::Map);
  const YAML::Node given = Child(root, "scene");
  if (given.IsDefined() && !given.IsNull() && r.ExpectMap(given, "scene")) {
    scene = YAML::Clone(given);
  }
  // line.belts: paper 1's shorthand for the scene's belts, item by item
  // (an item past the scene's list adds a belt). The scene file checks the
  // keys; what is wrong is reported here, where the user wrote it.
  const YAML::Node line = b.Section(root, "", "line", {"belts"});
  const YAML::Node belts = Child(line, "belts");
  if (belts.IsDefined() && !belts.IsNull() && r.ExpectSequence(belts, "line.belts")) {
    YAML::Node merged = scene["belts"];
    if (!merged.IsSequence()) merged = YAML::Node(YAML::NodeType::Sequence);
    for (std::size_t i = 0; i < belts.size(); ++i) {
      const std::string path = JoinPath("line.belts", std::to_string(i));
      if (!r.ExpectMap(belts[i], path)) continue;
      while (merged.size() <= i) merged.push_back(YAML::Node(YAML::NodeType::Map));
      YAML::Node item = merged[i];
      for (const auto& kv : belts[i]) {
        const std::string key = kv.first.Scalar();
        item[key] = kv.second;
        b.Derived("scene.belts." + std::to_string(i) + "." + key, belts[i], path, key);
      }
      b.Origin("scene.belts." + std::to_string(i), {belts[i], path, ""});
    }
    scene["belts"] = merged;
  }
  b.out()["scene"] = scene;
  // The scene as the system loader will read it; its problems are reported
  // now, at the keys the user wrote (the expansion stops on them, so they
  // are not reported twice).
  r.SetOrigins(b.origins());
  return ReadScenarioScene(r, scene, r.file());
}

void AddLine(SystemBuilder& b, const models::Scene& scene, Signals& s) {
  s.belt_count = scene.belts.size();
  if (s.belt_count == 0) return;
  // The belt unit drives every belt of the scene; it takes them from there.
  b.Unit(kBelt, "belt");
  b.Connect(Signal(kBelt, "velocity"), Signal(kChassis, "belt_velocity"));
  b.Connect(Signal(kBelt, "travel"), Signal(kChassis, "belt_travel"));
  for (const char* v : {"speed", "on", "travel"}) s.recorded.push_back(Signal(kBelt, v));
}

}  // namespace linesim::loader::assembly
