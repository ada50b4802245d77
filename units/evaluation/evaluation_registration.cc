// Registers the evaluation family's unit types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/evaluation/path_deviation.h"

namespace linesim::evaluation {
namespace {

using config::ReadPoints;
using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakePathDeviation(const UnitBuildContext& c) {
  return std::make_unique<evaluation::PathDeviationUnit>(c.name, ReadPoints(c, "path", 1));
}

const config::UnitTypeRegistrar kPathDeviation(
    {evaluation::PathDeviationUnit::kTypeName,
     "ground-truth distance of the robot centre from its desired path or held point",
     "",
     {{"path", "list of points [x, y] (m): a polyline, or one point for a hold"}},
     MakePathDeviation});

}  // namespace
}  // namespace linesim::evaluation
