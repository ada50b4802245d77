// Registers paper 2's Perfect Match localization (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/estimation/beam_counts.h"
#include "units/estimation/perfect_match_localization_unit.h"

namespace linesim::estimation {
namespace {

using config::UnitBuildContext;
using Unit = PerfectMatchLocalizationUnit;

std::optional<std::vector<Unit::MapSpec>> ReadMaps(const UnitBuildContext& c) {
  const YAML::Node list = config::Child(c.parameters, "maps");
  const std::string path = config::JoinPath(c.path, "maps");
  if (!list.IsDefined() || list.IsNull()) {
    c.reader.Error(c.parameters, c.path,
                   "maps is required: a list of {name, height_m, region (optional): {min_x_m, "
                   "max_x_m, min_y_m, max_y_m}}, e.g. [{name: factory, height_m: 0.35}]");
    return std::nullopt;
  }
  if (!c.reader.ExpectSequence(list, path)) return std::nullopt;
  if (list.size() < 1 || list.size() > Unit::kMaxMaps) {
    c.reader.Error(list, path,
                   "maps must list 1 to " + std::to_string(Unit::kMaxMaps) + " maps, got " +
                       std::to_string(list.size()));
    return std::nullopt;
  }
  std::vector<Unit::MapSpec> maps;
  bool ok = true;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node m = list[i];
    const std::string mp = config::JoinPath(path, std::to_string(i));
    if (!c.reader.ExpectMap(m, mp)) {
      ok = false;
      continue;
    }
    c.reader.CheckKeys(m, mp, {"name", "height_m", "floor_m", "region", "cell_m", "source"});
    Unit::MapSpec spec;
    spec.name = c.reader.String(m, mp, "name", std::nullopt);
    spec.height_m = c.reader.Real(m, mp, "height_m", std::nullopt, {-100.0, 100.0});
    spec.cell_m = c.reader.Real(m, mp, "cell_m", 0.0, {0.0, 0.5});
    spec.floor_m = c.reader.Real(m, mp, "floor_m", 0.0, {-100.0, 100.0});
    spec.from_own_laser =
        c.reader.String(m, mp, "source", "geometry", {"geometry", "own_laser"}) == "own_laser";
    for (std::size_t j = 0; j < maps.size(); ++j) {
      if (maps[j].name == spec.name) {
        c.reader.Error(m, mp, "map name '" + spec.name + "' is used twice");
        ok = false;
      }
    }
    const YAML::Node r = config::Child(m, "region");
    if (r.IsDefined() && !r.IsNull()) {
      const std::string rp = config::JoinPath(mp, "region");
      if (!c.reader.ExpectMap(r, rp)) {
        ok = false;
      } else {
        c.reader.CheckKeys(r, rp, {"min_x_m", "max_x_m", "min_y_m", "max_y_m"});
        DistanceMap::Region g;
        g.min_x = c.reader.Real(r, rp, "min_x_m", std::nullopt, {-1e4, 1e4});
        g.max_x = c.reader.Real(r, rp, "max_x_m", std::nullopt, {-1e4, 1e4});
        g.min_y = c.reader.Real(r, rp, "min_y_m", std::nullopt, {-1e4, 1e4});
        g.max_y = c.reader.Real(r, rp, "max_y_m", std::nullopt, {-1e4, 1e4});
        if (!(g.max_x > g.min_x && g.max_y > g.min_y)) {
          c.reader.Error(r, rp, "the region needs max_x_m > min_x_m and max_y_m > min_y_m");
          ok = false;
        }
        spec.region = g;
      }
    }
    maps.push_back(std::move(spec));
  }
  if (!ok) return std::nullopt;
  return maps;
}

std::unique_ptr<cosim::Unit> MakePerfectMatch(const UnitBuildContext& c) {
  const bool inspect = !c.parameters.IsDefined() || c.parameters.IsNull();
  if (inspect) {
    // `linesim inspect perfect_match_localization`: one laser of one beam, one map.
    return std::make_unique<Unit>(c.name, c.scene, std::vector<int>{1},
                                  std::vector<Unit::MapSpec>{{"map", 0.35, std::nullopt}});
  }
  const std::size_t issues = c.reader.issues().size();
  const auto beams = ReadBeamCounts(c, "e.g. [541] for the LMS151 at 0.5 deg");
  const auto maps = ReadMaps(c);
  if (!beams || !maps || c.reader.issues().size() != issues) return nullptr;
  return std::make_unique<Unit>(c.name, c.scene, *beams, *maps);
}

const config::UnitTypeRegistrar kPerfectMatch(
    {Unit::kTypeName,
     "laser localization of paper 2 (Sobreira et al. 2019, Sec. 4): Perfect Match (Lauer, Lange, "
     "Riedmiller 2005; RPROP on sum 1 - c^2 / (c^2 + d^2) over a distance map) of each new scan "
     "against one of several maps (horizontal slices of the scene), chosen by map_index; the "
     "covariance from the error's curvature, for pose_fusion",
     "",
     {{"beam_counts",
       "one entry per laser: its beam count (the size of its ranges_<k> input), e.g. [541]"},
      {"maps",
       "the maps, in map_index order: each {name, height_m (the slice's z above the floor), "
       "floor_m (optional, 0: the z of the floor its outlines stand on; with attitude terrain "
       "points below it plus ground_clearance are dropped), "
       "region (optional, {min_x_m, max_x_m, min_y_m, max_y_m}: only the solids whose footprint "
       "lies inside it; absent: every static solid), cell_m (optional: its lookup grid's cell, "
       "else the lookup_cell parameter), source (optional: geometry, the default, a map of the "
       "scene's solids as drawn; own_laser, built by SLAM with the robot's lasers, whose range "
       "bias its outlines then carry: see the mapping_range_bias inputs)}"}},
     MakePerfectMatch});

}  // namespace
}  // namespace linesim::estimation
