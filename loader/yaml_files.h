#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <string>
#include <vector>

#include "loader/config_names.h"

namespace linesim::loader {

/// A YAML file read whole, or why it could not be.
struct YamlFile {
  enum class Problem { kNone, kMissing, kFolder, kInvalid, kUnreadable };
  YAML::Node root;
  Problem problem = Problem::kNone;
  std::string detail;  // the parser's or the system's words
  int line = 0;        // of invalid YAML; 0 when unknown
};

/// The largest YAML file linesim reads (scenario, robot, scene, sweep and
/// model files), checked before parsing: the repository's largest is 9 KB,
/// and yaml-cpp needs some 50 times a file's size in memory, so 4 MiB
/// bounds a read to a few hundred MB.
inline constexpr std::uintmax_t kMaxYamlBytes = std::uintmax_t{4} << 20;

/// Reads `file` (a folder is refused before yaml-cpp, which would leak its
/// buffer reading one; a file larger than kMaxYamlBytes before reading it);
/// never throws.
YamlFile LoadYamlFile(const std::string& file);

/// The tree of `file`, or ScenarioError naming the file (and the line of
/// invalid YAML). `kind` words the messages: "sweep" gives "cannot read the
/// sweep file"; empty gives "cannot read the file".
YAML::Node LoadYamlOrThrow(const std::string& file, const std::string& kind = "");

/// Names of the model files in models/`folder`, sorted.
std::vector<std::string> ModelNames(const std::string& folder);

/// Reads the model `value` names: a name of a file in models/`folder`, or a
/// path (with '/' or ending in .yaml) relative to `relative_to`'s folder.
/// Problems are reported at `at`/`path` through `r`, "no <what> file F
/// (closest: ...)" or "cannot read <what> file F: why"; then the result is
/// an undefined node. `file` receives the file's path.
YAML::Node LoadModel(YamlReader& r, const YAML::Node& at, const std::string& path,
                     const std::string& what, const std::string& value, const std::string& folder,
                     const std::string& relative_to, std::string* file = nullptr);

}  // namespace linesim::loader
