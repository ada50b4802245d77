#include "models/models_dir.h"

#include <cstdlib>

namespace linesim::models {

std::string ModelsDir() {
  if (const char* env = std::getenv("LINESIM_MODELS_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  return LINESIM_DEFAULT_MODELS_DIR;
}

}  // namespace linesim::models
