// Registers the route_follower unit type (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/control/route_follower_unit.h"

namespace linesim::control {
namespace {

using config::Child;
using config::JoinPath;
using config::UnitBuildContext;

// A list of polynomial coefficients (m) at `path`.
std::vector<double> ReadCoefficients(const UnitBuildContext& c, const YAML::Node& item,
                                     const std::string& path, const char* key) {
  std::vector<double> out;
  const YAML::Node list = Child(item, key);
  const std::string at = JoinPath(path, key);
  if (!list.IsDefined() || list.IsNull()) {
    c.reader.Error(item, at, "missing required key: a list of polynomial coefficients (m)");
    return out;
  }
  if (!c.reader.ExpectSequence(list, at)) return out;
  if (list.size() == 0 || list.size() > models::kMaxPolynomialCoefficients) {
    c.reader.Error(list, at,
                   std::to_string(list.size()) + " coefficients: expected 1 to " +
                       std::to_string(models::kMaxPolynomialCoefficients) + " (degree 0 to " +
                       std::to_string(models::kMaxPolynomialCoefficients - 1) + ")");
    return out;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (auto a = c.reader.AsReal(list[i], JoinPath(at, std::to_string(i)), {-1e6, 1e6})) {
      out.push_back(*a);
    }
  }
  return out;
}

std::unique_ptr<cosim::Unit> MakeRouteFollower(const UnitBuildContext& c) {
  std::vector<models::PolynomialSegment> segments;
  if (!c.parameters.IsDefined() || c.parameters.IsNull()) {
    // `linesim inspect route_follower`: one metre along +x.
    segments.push_back({{0.0, 1.0}, {0.0}, 0});
    return std::make_unique<RouteFollowerUnit>(c.name, std::move(segments));
  }
  const std::string path = JoinPath(c.path, "segments");
  const YAML::Node list = Child(c.parameters, "segments");
  const std::size_t before = c.reader.issues().size();
  if (!list.IsDefined() || list.IsNull()) {
    c.reader.Error(c.parameters, path,
                   "missing required key: a list of segments {x: [A0, ...], y: [B0, ...], map: "
                   "index}");
    return nullptr;
  }
  if (!c.reader.ExpectSequence(list, path)) return nullptr;
  // A stated limit, as for the path follower's waypoints.
  constexpr std::size_t kMaxSegments = 10000;
  if (list.size() == 0 || list.size() > kMaxSegments) {
    c.reader.Error(
        list, path,
        std::to_string(list.size()) + " segments: expected 1 to " + std::to_string(kMaxSegments));
    return nullptr;
  }
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string at = JoinPath(path, std::to_string(k));
    if (!c.reader.ExpectMap(list[k], at)) continue;
    c.reader.CheckKeys(list[k], at, {"x", "y", "map"});
    models::PolynomialSegment s;
    s.x = ReadCoefficients(c, list[k], at, "x");
    s.y = ReadCoefficients(c, list[k], at, "y");
    s.map = static_cast<int>(c.reader.Integer(list[k], at, "map", 0, 0, 1000));
    segments.push_back(std::move(s));
  }
  if (c.reader.issues().size() != before) return nullptr;
  return std::make_unique<RouteFollowerUnit>(c.name, std::move(segments));
}

const config::UnitTypeRegistrar kRouteFollower(
    {RouteFollowerUnit::kTypeName,
     "paper 2's parametric trajectory controller (Sobreira et al. 2019, Sec. 5, Eqs. 1-17): "
     "a unicycle-steered base (differential; a swerve base with vy = 0) follows polynomial "
     "segments at a constant speed, yaw rate from the "
     "distance and orientation errors (PI, switched by T_theta) plus the curvature "
     "feed-forward; stops on the final point; outputs the current segment's map index",
     "",
     {{"segments",
       "list of {x: [A0, A1, ...], y: [B0, B1, ...], map: index}: Fx(t) = sum A_i t^i, "
       "Fy(t) = sum B_i t^i (m), t in [0, 1], one continuous path; map (default 0) is the "
       "localization map of the segment"}},
     MakeRouteFollower});

}  // namespace
}  // namespace linesim::control
