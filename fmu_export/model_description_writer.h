#pragma once
// modelDescription.xml (FMI 2.0 co-simulation) for a linesim unit, from its
// VariableTable through the Layout the FMU runtime serves.

#include <string>

#include "cosim/unit.h"
#include "fmu_export/export_layout.h"

namespace linesim::fmu_export {

struct DescriptionInfo {
  std::string model_name;        // the unit type ("dc_motor")
  std::string model_identifier;  // the binary's name, a C identifier
  std::string guid;
  std::string description;
};

/// The model description: every scalar of `layout` with its causality,
/// variability, type, start value (parameters and inputs), unit, declared
/// range as min / max (a parameter's Rule), description; UnitDefinitions
/// with each unit's SI base units; ModelStructure's outputs with their
/// direct dependencies (the table's depends_on) and initial unknowns;
/// CoSimulation with canGetAndSetFMUstate and canSerializeFMUstate.
std::string WriteModelDescription(const cosim::Unit& unit, const Layout& layout,
                                  const DescriptionInfo& info);

/// The FMI 3.0 co-simulation model description: the value reference of a
/// variable is its index in the table, a Real array one Float64 variable
/// with its fixed <Dimension>; linesim Integers are Int32 (as the FMI 2.0
/// export's Integer); otherwise as WriteModelDescription.
std::string WriteModelDescription3(const cosim::Unit& unit, const DescriptionInfo& info);

}  // namespace linesim::fmu_export
