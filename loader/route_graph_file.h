#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

#include "loader/config_names.h"
#include "models/polynomial_path.h"

/// Route graphs (models/graphs/*.yaml): a fixed graph of poses over the map
/// whose edges are polynomial segments (paper 2, Sobreira et al. 2019, Sec.
/// 5: "the robot ... will perform a fixed trajectory"), and routes through
/// it as lists of node names. The format is described at the top of
/// models/graphs/van_bay.yaml and in the README ("Route graphs").
namespace linesim::loader {

struct RouteGraphNode {
  std::string name;
  double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0;
};

struct RouteGraphEdge {
  std::string from, to;
  /// The edge as a segment, its `map` the index of the edge's map in
  /// RouteGraph::maps: the explicit coefficients, or the cubic Hermite
  /// between the two node poses.
  models::PolynomialSegment segment;
};

struct RouteGraph {
  std::string file;
  std::vector<std::string> maps;  // a map's index is its map_index
  std::vector<RouteGraphNode> nodes;
  std::vector<RouteGraphEdge> edges;
};

/// Reads a graph from `root` (`r` reads the graph file: its issues name it),
/// reporting every problem at its key path (nodes.2.yaw_deg, edges.0.to):
/// unknown keys with the closest, wrong types, values out of range, missing
/// required keys, a node or edge defined twice, an edge naming an unknown
/// node or map, explicit coefficients that do not start and end on the
/// edge's nodes (1 mm). Nothing when there was a problem.
std::optional<RouteGraph> ReadRouteGraph(YamlReader& r, const YAML::Node& root,
                                         const std::string& file);

/// The graph file `file`, or ScenarioError listing every problem.
RouteGraph LoadRouteGraphFile(const std::string& file);

/// The graph that `value` names: models/graphs/VALUE.yaml, or a path (with
/// '/' or ending in .yaml) relative to `relative_to`'s folder. A missing or
/// unreadable file is reported at `at` / `path`; the file's own problems in
/// the file.
std::optional<RouteGraph> ReadRouteGraphModel(YamlReader& r, const YAML::Node& at,
                                              const std::string& path, const std::string& value,
                                              const std::string& relative_to);

/// The segments of a route through `graph`: `route` is a list of at least
/// two node names, each consecutive pair an edge of the graph (directed:
/// from, to). Problems at `path`.i: an unknown node (with the closest
/// names), a pair without an edge (naming both nodes and the graph file).
std::optional<std::vector<models::PolynomialSegment>> RouteSegments(YamlReader& r,
                                                                    const RouteGraph& graph,
                                                                    const YAML::Node& route,
                                                                    const std::string& path);

}  // namespace linesim::loader
