// Registers the fmu family's unit type (see config/unit_registry.h).
#include <filesystem>

#include "config/input_files.h"
#include "config/unit_registry.h"
#include "units/fmu/fmu_unit.h"

namespace linesim::fmu {
namespace {

using config::Child;
using config::JoinPath;
using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakeFmu(const UnitBuildContext& c) {
  // No parameters at all (`linesim inspect fmu`): a unit without an FMU,
  // which reports that `path` must be set.
  if (!c.parameters.IsDefined() || c.parameters.IsNull()) {
    return std::make_unique<FmuUnit>(c.name);
  }
  const std::string path = c.reader.String(c.parameters, c.path, "path", std::nullopt);
  if (path.empty()) return nullptr;
  // Relative to the scenario file (the reader's file while units are made).
  std::filesystem::path file(path);
  if (file.is_relative()) {
    file = std::filesystem::path(c.reader.file()).parent_path() / file;
  }
  // The FMU is a file the run's results depend on (config/input_files.h).
  config::RecordInputFile(file.string());
  try {
    return std::make_unique<FmuUnit>(c.name, file.lexically_normal().string());
  } catch (const FmuError& e) {
    c.reader.Error(Child(c.parameters, "path"), JoinPath(c.path, "path"), e.what());
    return nullptr;
  }
}

const config::UnitTypeRegistrar kFmu(
    {FmuUnit::kTypeName,
     "an FMI 2.0 or 3.0 co-simulation FMU: its parameters, inputs and outputs as the FMU "
     "declares them (`linesim inspect FILE.fmu` lists them)",
     "",
     {{"path", "the FMU file (.fmu), relative to the scenario file"}},
     MakeFmu});

}  // namespace
}  // namespace linesim::fmu
