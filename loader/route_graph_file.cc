#include "loader/route_graph_file.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

#include "cosim/closest_names.h"
#include "cosim/variable_table.h"
#include "loader/yaml_files.h"
#include "models/angle.h"

namespace linesim::loader {

namespace {

// Positions on the floor: the scene files' bound.
constexpr Range kCoordinate{-1e6, 1e6};
// A heading in degrees, one turn either way.
constexpr Range kYawDeg{-360.0, 360.0};
// Hermite tangent lengths: as long as a hall.
constexpr Range kTangent{0.0, 1e4, true};
// Explicit coefficients end within 1 mm of the edge's nodes (rounding of
// hand-written numbers), as the follower joins its segments.
constexpr double kEndTolerance = 1e-3;

// The items of a required list of maps at `key` of `root`.
std::vector<std::pair<std::string, YAML::Node>> Items(YamlReader& r, const YAML::Node& root,
                                                      const std::string& key,
                                                      const std::string& what) {
  std::vector<std::pair<std::string, YAML::Node>> items;
  const YAML::Node list = Child(root, key);
  if (!list.IsDefined() || list.IsNull()) {
    r.Error(root, key, "missing required key: a list of " + what);
    return items;
  }
  if (!r.ExpectSequence(list, key)) return items;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string path = JoinPath(key, std::to_string(i));
    if (r.ExpectMap(list[i], path)) items.emplace_back(path, list[i]);
  }
  return items;
}

// A name at `key` of `item` that must be one of `names`.
std::optional<std::size_t> Reference(YamlReader& r, const YAML::Node& item, const std::string& path,
                                     const std::string& key, const std::vector<std::string>& names,
                                     const std::string& what) {
  const std::string name = r.String(item, path, key, std::nullopt);
  if (name.empty()) return std::nullopt;  // reported (missing or not text)
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    r.Error(Child(item, key), JoinPath(path, key),
            "no " + what + " '" + name + "' in this graph: expected one of " + JoinNames(names) +
                cosim::ClosestHint(name, names));
    return std::nullopt;
  }
  return static_cast<std::size_t>(it - names.begin());
}

// Explicit coefficients at `key` (a list of 1 to 16 numbers, m).
std::vector<double> Coefficients(YamlReader& r, const YAML::Node& item, const std::string& path,
                                 const std::string& key) {
  std::vector<double> out;
  const YAML::Node list = Child(item, key);
  const std::string at = JoinPath(path, key);
  if (!r.ExpectSequence(list, at)) return out;
  if (list.size() == 0 || list.size() > models::kMaxPolynomialCoefficients) {
    r.Error(list, at,
            std::to_string(list.size()) + " coefficients: expected 1 to " +
                std::to_string(models::kMaxPolynomialCoefficients) + " numbers [A0, A1, ...] (m)");
    return out;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (auto a = r.AsReal(list[i], JoinPath(at, std::to_string(i)), kCoordinate)) {
      out.push_back(*a);
    }
  }
  return out.size() == list.size() ? out : std::vector<double>{};
}

}  // namespace

std::optional<RouteGraph> ReadRouteGraph(YamlReader& r, const YAML::Node& root,
                                         const std::string& file) {
  const std::size_t before = r.issues().size();
  RouteGraph g;
  g.file = file;
  if (!r.ExpectMap(root, "(top)")) return std::nullopt;
  r.CheckKeys(root, "", {"description", "source", "maps", "nodes", "edges"});
  r.String(root, "", "description", "");  // documentation only; must be text
  r.String(root, "", "source", "");

  // Maps: names, in the order of their map_index.
  const YAML::Node maps = Child(root, "maps");
  if (!maps.IsDefined() || maps.IsNull()) {
    r.Error(root, "maps",
            "missing required key: a list of map names (a map's index is its "
            "map_index)");
  } else if (r.ExpectSequence(maps, "maps")) {
    for (std::size_t i = 0; i < maps.size(); ++i) {
      const std::string path = JoinPath("maps", std::to_string(i));
      const auto name = r.AsString(maps[i], path);
      if (!name) continue;
      if (name->empty()) {
        r.Error(maps[i], path, "expected a map name, got an empty text");
      } else if (std::find(g.maps.begin(), g.maps.end(), *name) != g.maps.end()) {
        r.Error(maps[i], path, "'" + *name + "' is listed twice: names must differ");
      }
      g.maps.push_back(*name);
    }
  }

  std::vector<std::string> node_names;
  for (const auto& [path, item] : Items(r, root, "nodes", "nodes {name, x_m, y_m, yaw_deg}")) {
    r.CheckKeys(item, path, {"name", "x_m", "y_m", "yaw_deg"});
    RouteGraphNode n;
    n.name = r.String(item, path, "name", std::nullopt);
    if (!n.name.empty() &&
        std::find(node_names.begin(), node_names.end(), n.name) != node_names.end()) {
      r.Error(Child(item, "name"), JoinPath(path, "name"),
              "'" + n.name + "' is defined twice in this list: names must differ");
    }
    n.x_m = r.Real(item, path, "x_m", std::nullopt, kCoordinate);
    n.y_m = r.Real(item, path, "y_m", std::nullopt, kCoordinate);
    n.yaw_rad = r.Real(item, path, "yaw_deg", std::nullopt, kYawDeg) * models::kDegToRad;
    node_names.push_back(n.name);
    g.nodes.push_back(std::move(n));
  }

  for (const auto& [path, item] :
       Items(r, root, "edges", "edges {from, to, map, optional x, y or tangent_m}")) {
    r.CheckKeys(item, path, {"from", "to", "map", "x", "y", "tangent_m"});
    const auto from = Reference(r, item, path, "from", node_names, "node");
    const auto to = Reference(r, item, path, "to", node_names, "node");
    const auto map = Reference(r, item, path, "map", g.maps, "map");
    const bool has_x = Child(item, "x").IsDefined(), has_y = Child(item, "y").IsDefined();
    const bool has_tangent = Child(item, "tangent_m").IsDefined();
    if (has_x != has_y) {
      r.Error(item, JoinPath(path, has_x ? "y" : "x"),
              "missing required key: explicit coefficients need both x and y");
    }
    if ((has_x || has_y) && has_tangent) {
      r.Error(Child(item, "tangent_m"), JoinPath(path, "tangent_m"),
              "only for the Hermite edge between the node poses: leave it out with explicit x, y");
    }
    const double tangent = has_tangent ? r.Real(item, path, "tangent_m", 0.0, kTangent) : 0.0;
    if (!from || !to || !map) continue;
    if (*from == *to) {
      r.Error(Child(item, "to"), JoinPath(path, "to"),
              "an edge from '" + g.nodes[*from].name + "' to itself: expected another node");
      continue;
    }
    const bool twice = std::any_of(g.edges.begin(), g.edges.end(), [&](const RouteGraphEdge& e) {
      return e.from == g.nodes[*from].name && e.to == g.nodes[*to].name;
    });
    if (twice) {
      r.Error(item, path,
              "a second edge from '" + g.nodes[*from].name + "' to '" + g.nodes[*to].name +
                  "': one edge per direction");
      continue;
    }
    const RouteGraphNode& a = g.nodes[*from];
    const RouteGraphNode& b = g.nodes[*to];
    RouteGraphEdge e;
    e.from = a.name;
    e.to = b.name;
    if (has_x && has_y) {
      e.segment.x = Coefficients(r, item, path, "x");
      e.segment.y = Coefficients(r, item, path, "y");
      if (e.segment.x.empty() || e.segment.y.empty()) continue;
      e.segment.map = static_cast<int>(*map);
      for (const auto& [t, node, end] :
           {std::tuple{0.0, &a, "start"}, std::tuple{1.0, &b, "end"}}) {
        const models::Point2 p = models::SegmentPosition(e.segment, t);
        const double off = std::hypot(p[0] - node->x_m, p[1] - node->y_m);
        if (off > kEndTolerance) {
          r.Error(Child(item, "x"), JoinPath(path, "x"),
                  std::string("the coefficients ") + end + " at (" + cosim::FormatValue(p[0]) +
                      ", " + cosim::FormatValue(p[1]) + "), " +
                      cosim::FormatValue(std::round(off * 1e6) / 1e6) + " m from node '" +
                      node->name + "': expected within 1 mm of it");
        }
      }
    } else if (!has_x && !has_y) {
      if (std::hypot(b.x_m - a.x_m, b.y_m - a.y_m) == 0.0 && !has_tangent) {
        r.Error(item, path,
                "nodes '" + a.name + "' and '" + b.name +
                    "' are at the same place: the Hermite edge needs tangent_m");
        continue;
      }
      e.segment = models::HermiteSegment(a.x_m, a.y_m, a.yaw_rad, b.x_m, b.y_m, b.yaw_rad, tangent,
                                         static_cast<int>(*map));
    } else {
      continue;
    }
    g.edges.push_back(std::move(e));
  }
  if (r.issues().size() != before) return std::nullopt;
  return g;
}

RouteGraph LoadRouteGraphFile(const std::string& file) {
  const YAML::Node root = LoadYamlOrThrow(file, "route graph");
  YamlReader r(file);
  auto graph = ReadRouteGraph(r, root, file);
  if (!r.ok() || !graph) throw ScenarioError(r.issues());
  return *graph;
}

std::optional<RouteGraph> ReadRouteGraphModel(YamlReader& r, const YAML::Node& at,
                                              const std::string& path, const std::string& value,
                                              const std::string& relative_to) {
  std::string file;
  const YAML::Node root =
      LoadModel(r, at, path, "route graph", value, "graphs", relative_to, &file);
  if (!root.IsDefined()) return std::nullopt;
  YamlReader::InFile in(r, file);
  return ReadRouteGraph(r, root, file);
}

std::optional<std::vector<models::PolynomialSegment>> RouteSegments(YamlReader& r,
                                                                    const RouteGraph& graph,
                                                                    const YAML::Node& route,
                                                                    const std::string& path) {
  if (!route.IsDefined() || route.IsNull()) {
    r.Error(route, path, "missing required key: a list of node names");
    return std::nullopt;
  }
  if (!r.ExpectSequence(route, path)) return std::nullopt;
  if (route.size() < 2) {
    r.Error(route, path, "expected at least two node names (one edge)");
    return std::nullopt;
  }
  std::vector<std::string> names;
  for (const auto& n : graph.nodes) names.push_back(n.name);
  const std::size_t before = r.issues().size();
  std::vector<std::string> stops;
  for (std::size_t i = 0; i < route.size(); ++i) {
    const std::string at = JoinPath(path, std::to_string(i));
    const auto name = r.AsString(route[i], at);
    if (!name) continue;
    if (std::find(names.begin(), names.end(), *name) == names.end()) {
      r.Error(route[i], at,
              "no node '" + *name + "' in route graph " + graph.file +
                  cosim::ClosestHint(*name, names));
      continue;
    }
    stops.push_back(*name);
  }
  if (r.issues().size() != before) return std::nullopt;
  std::vector<models::PolynomialSegment> segments;
  for (std::size_t i = 0; i + 1 < stops.size(); ++i) {
    const auto edge = std::find_if(graph.edges.begin(), graph.edges.end(), [&](const auto& e) {
      return e.from == stops[i] && e.to == stops[i + 1];
    });
    if (edge == graph.edges.end()) {
      std::vector<std::string> onward;
      for (const auto& e : graph.edges) {
        if (e.from == stops[i]) onward.push_back(e.to);
      }
      r.Error(route[i + 1], JoinPath(path, std::to_string(i + 1)),
              "no edge from '" + stops[i] + "' to '" + stops[i + 1] + "' in route graph " +
                  graph.file + ": edges from '" + stops[i] + "' go to " +
                  (onward.empty() ? std::string("no node") : JoinNames(onward)));
      continue;
    }
    segments.push_back(edge->segment);
  }
  if (r.issues().size() != before) return std::nullopt;
  return segments;
}

}  // namespace linesim::loader
