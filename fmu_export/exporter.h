#pragma once
// `linesim export-fmu`: a registered unit type as an FMI 2.0 co-simulation
// FMU whose binary is the linesim FMU runtime (fmu_runtime.cc).

#include <stdexcept>
#include <string>
#include <vector>

namespace linesim::fmu_export {

/// A refusal of the export, worded for the user.
class ExportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ExportOptions {
  std::string type;               // a registered unit type
  std::vector<std::string> sets;  // "key=value": structural keys, `model`, parameters
  std::string out;                // NAME.fmu
  /// The runtime library to ship; empty: the one this build made
  /// (RuntimeLibraryPath()).
  std::string runtime_library;
  /// The scene a unit that takes geometry from it (belt, sensors) is built
  /// for: a name of models/scenes/ or a path; empty: the open floor. The
  /// file goes into the FMU (resources/scene.yaml).
  std::string scene;
  /// 2 or 3; 0: FMI 3.0 when the unit has a Real array of more than one
  /// element (kept whole as an FMI 3.0 array), else FMI 2.0.
  int fmi_version;
};

struct ExportResult {
  int fmi_version = 2;
  std::string model_identifier;
  std::string guid;
  std::size_t variables = 0;  // FMI variables (FMI 2.0: scalars)
  std::string model_description;
  std::string resource;       // resources/linesim_unit.yaml
};

/// Builds the unit as a scenario would (the model file, then the --set
/// values, checked by the loader with the same messages), and writes `out`:
///   modelDescription.xml                  from the unit's VariableTable
///   resources/linesim_unit.yaml           the type and every parameter value
///   resources/scene.yaml                  the scene file, with `scene`
///   binaries/linux64/<type>.so            the linesim FMU runtime (FMI 2.0;
///   binaries/x86_64-linux/<type>.so       FMI 3.0)
/// Throws ExportError: an unknown type, a bad key or value, a variable FMI
/// 2.0 cannot carry, a missing runtime library, a file that cannot be written.
ExportResult ExportFmu(const ExportOptions& options);

/// The runtime library to ship: an installed linesim's (lib/linesim/ of
/// its prefix), else the one this build made (next to the linesim binary in
/// the build tree).
std::string RuntimeLibraryPath();

/// The resource files inside an FMU, relative to its resources folder.
inline constexpr const char* kResourceFile = "linesim_unit.yaml";
inline constexpr const char* kSceneFile = "scene.yaml";

}  // namespace linesim::fmu_export
