#pragma once

// The loader reads with the config library (config/): these names are the
// loader's own as well, so loader code and its callers write YamlReader,
// loader::ScenarioError, FindUnitType.

#include "config/scenario_error.h"
#include "config/unit_registry.h"
#include "config/yaml_reader.h"

namespace linesim::loader {

using config::Child;
using config::ClosestPathsHint;
using config::Describe;
using config::FindUnitType;
using config::Issue;
using config::JoinNames;
using config::JoinPath;
using config::Origin;
using config::Range;
using config::ScenarioError;
using config::UnitType;
using config::UnitTypeNames;
using config::UnknownTypeMessage;
using config::YamlReader;

}  // namespace linesim::loader
