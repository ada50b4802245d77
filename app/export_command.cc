// `linesim export-fmu`: see fmu_export/exporter.h.
#include <iostream>

#include "app/commands.h"
#include "fmu_export/exporter.h"

namespace linesim::app {

int ExportFmuCommand(const std::string& type, const std::vector<std::string>& set_args,
                     const std::string& scene, int fmi_version, const std::string& out) {
  try {
    const auto result = fmu_export::ExportFmu({type, set_args, out, "", scene, fmi_version});
    std::cout << "wrote " << out << ": FMI " << result.fmi_version
              << ".0 co-simulation, model identifier '"
              << result.model_identifier << "', " << result.variables << " variables, guid "
              << result.guid << "\n";
    return kExitOk;
  } catch (const fmu_export::ExportError& e) {
    std::cerr << "linesim export-fmu: " << e.what() << "\n";
    return kExitBadInput;
  }
}

}  // namespace linesim::app
