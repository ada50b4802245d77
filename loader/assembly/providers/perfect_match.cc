// The pose from Perfect Match and the odometry in an EKF (paper 2 Sec. 4).
// A provider (loader/assembly/providers.h): it registers itself.
#include <algorithm>
#include <optional>

#include "loader/assembly/providers.h"

namespace linesim::loader::assembly {
namespace {

// Perfect Match (paper 2 Sec. 4, after Lauer, Lange and Riedmiller 2005)
// on the robot's lasers against maps sliced from the scene at the scan
// height: `localization.maps` lists them ({name, floor_m, region, cell_m});
// a route's graph chooses one per segment (ConnectMapSwitch). Without the
// key, one map of the whole scene on the floor.
void AddPerfectMatch(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  YamlReader& r = b.reader();
  const auto lasers = Mounts(s, "laser_scanner");
  b.Unit(kPerfectMatch, "perfect_match_localization");
  Parameters& p = b.Params(kPerfectMatch);
  // The nearest usable range of all lasers, and the largest per-device
  // range bias (the LMS151's systematic error) for the match covariance.
  std::optional<double> range_min, bias_sigma;
  WireLasers(b, c, s, kPerfectMatch, true, [&](const DeviceNumbers& device) {
    if (const auto v = device.Get("range_min")) range_min = std::max(range_min.value_or(0.0), *v);
    if (const auto v = device.Get("bias_sigma"))
      bias_sigma = std::max(bias_sigma.value_or(0.0), *v);
  });
  // The maps a laser built by SLAM (source: own_laser) carry its device's
  // range bias.
  for (std::size_t k = 0; k < lasers.size(); ++k) {
    b.Connect(Signal(lasers[k]->name, "range_bias"),
              Signal(kPerfectMatch, "mapping_range_bias_" + std::to_string(k)));
  }
  if (range_min) p["range_min"] = *range_min;
  // The wheels' contact rectangle, for the attitude from known terrain
  // (parameter attitude terrain: the base's pitch and roll on a ramp).
  const auto& wheels = c.file.robot.wheels;
  if (!wheels.empty()) {
    double min_x = wheels.front().x_m, max_x = min_x, min_y = wheels.front().y_m, max_y = min_y;
    for (const auto& w : wheels) {
      min_x = std::min(min_x, w.x_m);
      max_x = std::max(max_x, w.x_m);
      min_y = std::min(min_y, w.y_m);
      max_y = std::max(max_y, w.y_m);
    }
    if (max_x > min_x) p["wheelbase"] = max_x - min_x;
    if (max_y > min_y) p["track"] = max_y - min_y;
    p["wheel_radius"] = wheels.front().radius_m;
  }
  if (bias_sigma) p["range_bias_sigma"] = *bias_sigma;
  // 3 DoF as paper 2's matcher: every map is a slice at the first laser's
  // height above the map's floor.
  const double scan_z = lasers.empty() ? 0.0 : lasers.front()->z_m;
  YAML::Node maps(YAML::NodeType::Sequence);
  const YAML::Node given = Child(c.at, "maps");
  if (!given.IsDefined()) {
    YAML::Node one;
    one["name"] = "scene";
    one["height_m"] = Num(scan_z);
    maps.push_back(one);
    s.localization_maps = {"scene"};
  } else if (r.ExpectSequence(given, "localization.maps")) {
    if (given.size() == 0) r.Error(given, "localization.maps", "expected at least one map");
    for (std::size_t i = 0; i < given.size(); ++i) {
      const std::string path = JoinPath("localization.maps", std::to_string(i));
      if (!r.ExpectMap(given[i], path)) continue;
      r.CheckKeys(given[i], path, {"name", "floor_m", "region", "cell_m", "source"});
      YAML::Node one;
      const std::string name = r.String(given[i], path, "name", std::nullopt);
      one["name"] = name;
      const double floor_m = r.Real(given[i], path, "floor_m", 0.0, {-10.0, 100.0});
      one["height_m"] = Num(floor_m + scan_z);
      one["floor_m"] = Num(floor_m);
      for (const char* key : {"region", "cell_m", "source"}) {
        if (Child(given[i], key).IsDefined()) one[key] = Child(given[i], key);
      }
      maps.push_back(one);
      s.localization_maps.push_back(name);
    }
  }
  p["maps"] = ParameterValue(maps);
  b.Origin(JoinPath(JoinPath(JoinPath("units", kPerfectMatch), "parameters"), "maps"),
           {given.IsDefined() ? given : c.at, given.IsDefined() ? "localization.maps" : c.path,
            r.file()});
  s.map_index_input = Signal(kPerfectMatch, "map_index");
  SetInitialPose(p, c.start);
  SetStep(b, kPerfectMatch);
  s.recorded.push_back(Signal(kPerfectMatch, "source"));
  s.recorded.push_back(Signal(kPerfectMatch, "laser_status"));
  s.recorded.push_back(Signal(kPerfectMatch, "map_in_use"));
  s.recorded.push_back(Signal(kPerfectMatch, "match_error"));
  s.localization_sources.push_back(Signal(kPerfectMatch, "source"));
}

// Paper 2 Sec. 4: Perfect Match on the laser fused with the (skid-steer)
// odometry in an EKF of the pose alone: off a belt the odometry has no
// surface offset to learn, so the fusion's offset states are held at 0.
void LocalizationPerfectMatch(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  const bool lasers = Require(b, c, s, "laser_scanner", "perfect_match");
  const bool encoders = Require(b, c, s, "wheel_encoder", "perfect_match");
  if (!lasers || !encoders) return;
  AddPerfectMatch(b, c, s);
  AddOdometry(b, c, s);
  b.Params(kPerfectMatch)["motion_prediction"] = "odometry";
  ConnectOdometryToMatcher(b, kPerfectMatch);
  AddPoseFusion(b, c, s, kPerfectMatch);
  // The attitude the matcher knows (0 unless its attitude is terrain)
  // projects the fusion's odometry on the map too.
  b.Connect(Signal(kPerfectMatch, "pitch"), Signal(kPoseFusion, "base_pitch"));
  b.Connect(Signal(kPerfectMatch, "roll"), Signal(kPoseFusion, "base_roll"));
  Parameters& f = b.Params(kPoseFusion);
  f["offset_random_walk"] = 0;
  f["initial_offset_sigma"] = 0;
}

const ProviderRegistrar kLocalizationPerfectMatch(ProviderRole::kLocalization, "perfect_match",
                                                  LocalizationPerfectMatch);

}  // namespace
}  // namespace linesim::loader::assembly
