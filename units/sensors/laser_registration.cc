// Registers the laser scanner (see config/unit_registry.h).
#include <optional>

#include "config/unit_registry.h"
#include "models/polygon.h"
#include "units/sensors/laser_scanner_unit.h"

namespace linesim::sensors {
namespace {

using config::UnitBuildContext;

// A structural key from the parameters, else from the model file; the
// node's file is the reader's while `in` lives.
struct Source {
  YAML::Node node;
  std::string path;
  bool from_model = false;
};

Source Find(const UnitBuildContext& c, const std::string& key) {
  if (c.parameters.IsMap() && config::Child(c.parameters, key).IsDefined()) {
    return {c.parameters, c.path, false};
  }
  if (c.model.IsMap() && config::Child(c.model, key).IsDefined()) return {c.model, "", true};
  return {c.parameters, c.path, false};
}

std::unique_ptr<cosim::Unit> MakeLaserScanner(const UnitBuildContext& c) {
  const bool inspect = (!c.parameters.IsDefined() || c.parameters.IsNull()) && !c.model.IsMap();
  const std::size_t issues_before = c.reader.issues().size();
  std::int64_t beams = 1;
  {
    const Source s = Find(c, "beam_count");
    std::optional<config::YamlReader::InFile> in;
    if (s.from_model) in.emplace(c.reader, c.model_file);
    beams = c.reader.Integer(s.node, s.path, "beam_count",
                             inspect ? std::optional<std::int64_t>(1) : std::nullopt, 1, 100000);
  }
  std::vector<std::array<double, 2>> field;
  {
    const Source s = Find(c, "protective_field");
    std::optional<config::YamlReader::InFile> in;
    if (s.from_model) in.emplace(c.reader, c.model_file);
    const YAML::Node list = config::Child(s.node, "protective_field");
    const std::string path = config::JoinPath(s.path, "protective_field");
    if (list.IsDefined() && !list.IsNull() && c.reader.ExpectSequence(list, path)) {
      if (list.size() < 3) {
        c.reader.Error(list, path, "a protective field needs at least 3 corners [x, y] (m)");
        return nullptr;
      }
      for (std::size_t i = 0; i < list.size(); ++i) {
        if (auto p = c.reader.AsPoint(list[i], config::JoinPath(path, std::to_string(i)))) {
          field.push_back(*p);
        }
      }
      // A degenerate polygon holds no point: an OSSD that never switches.
      if (const auto problem = models::PolygonProblem(field);
          problem && field.size() == list.size()) {
        c.reader.Error(list, path, "the protective field " + *problem);
      }
    }
  }
  // Only the scenario sets it (a property of the scene, not of the device).
  const auto moving = c.reader.Integer(c.parameters, c.path, "moving_cylinders", 0, 0, 100000);
  const auto boxes = c.reader.Integer(c.parameters, c.path, "moving_boxes", 0, 0, 100000);
  if (c.reader.issues().size() != issues_before) return nullptr;
  return std::make_unique<LaserScannerUnit>(c.name, c.scene, static_cast<int>(beams),
                                            std::move(field), c.seed, static_cast<int>(moving),
                                            static_cast<int>(boxes));
}

const config::UnitTypeRegistrar kLaserScanner(
    {LaserScannerUnit::kTypeName,
     "2D time-of-flight laser scanner (SICK S300, LMS151) cast in 3D against the scene "
     "(Embree): beams timed within the sweep, spot and mixed pixels, noise, bias, "
     "quantization, protective field",
     "sensors",
     {{"model", "model file from models/sensors/ (name) or a path relative to the scenario"},
      {"beam_count", "beams per scan (the size of `ranges`); from the model file if not given"},
      {"protective_field",
       "corners [x, y] (m, scanner frame) of the protective field polygon (adds "
       "field_clear and multiple_sampling); from the model file if not given; none if "
       "neither gives it"},
      {"moving_cylinders",
       "number of moving cylinders (workers' legs and torsos) the scanner sees: adds the input "
       "moving_cylinders, 7 numbers each (default 0)"},
      {"moving_boxes",
       "number of moving boxes (other robots' bodies) the scanner sees: adds the input "
       "moving_boxes, 10 numbers each (default 0)"}},
     MakeLaserScanner});

}  // namespace
}  // namespace linesim::sensors
