#include <functional>
#include <map>

#include "loader/assembly/concerns.h"

namespace linesim::loader::assembly {

namespace {

using Provider = std::function<void(SystemBuilder&, Signals&)>;

// Who measures the velocity of the surface under each wheel (base_link).
// The sensing issue adds the PX4Flow chain and the belt-contact detection
// here, each a provider that adds its units and sets s.surface_velocity.
const std::map<std::string, Provider>& SurfaceVelocityProviders() {
  static const std::map<std::string, Provider> providers = {
      {"ground_truth", [](SystemBuilder&, Signals& s) {
         s.surface_velocity = s.true_surface_velocity;
       }}};
  return providers;
}

// Who tells the controllers where the robot is. Laser localization and
// odometry fusion are further providers that set s.position and s.yaw.
const std::map<std::string, Provider>& LocalizationProviders() {
  static const std::map<std::string, Provider> providers = {
      {"ground_truth", [](SystemBuilder&, Signals& s) {
         s.position = s.true_position;
         s.yaw = s.true_yaw;
       }}};
  return providers;
}

std::vector<std::string> Names(const std::map<std::string, Provider>& providers) {
  std::vector<std::string> names;
  for (const auto& [name, provider] : providers) names.push_back(name);
  return names;
}

void Apply(SystemBuilder& b, Signals& s, const std::string& section, const std::string& key,
           const std::map<std::string, Provider>& providers) {
  const YAML::Node node = b.Section(b.root(), "", section, {key});
  const std::string choice =
      b.reader().String(node, section, key, "ground_truth", Names(providers));
  if (const auto it = providers.find(choice); it != providers.end()) it->second(b, s);
}

}  // namespace

void AddSensing(SystemBuilder& b, Signals& s) {
  Apply(b, s, "sensing", "surface_velocity", SurfaceVelocityProviders());
  Apply(b, s, "localization", "source", LocalizationProviders());
}

}  // namespace linesim::loader::assembly
