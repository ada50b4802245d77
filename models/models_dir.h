#pragma once

#include <string>

namespace linesim::models {

/// Folder of the YAML model files: $LINESIM_MODELS_DIR when set, else the
/// `models/` folder of the source tree this program was built from.
std::string ModelsDir();

}  // namespace linesim::models
