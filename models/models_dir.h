#pragma once

#include <string>

namespace linesim::models {

/// Folder of the YAML model files, the first that exists of:
/// $LINESIM_MODELS_DIR; the installed copy beside the code that asks
/// (`models/` next to the Python package's native module in a wheel;
/// PREFIX/share/linesim/models for PREFIX/bin/linesim or the package in
/// PREFIX/lib/python3/dist-packages); the `models/` folder of the source
/// tree this program was built from.
std::string ModelsDir();

/// The folder of the file this code is linked into: linesim's executable,
/// or a shared object (the Python package's native module) when it is
/// linked into one; "" when it cannot be found.
std::string CodeDir();

/// `relative` (a path relative to CodeDir(): where `cmake --install` puts
/// a file relative to the executable) when it exists, else "".
std::string InstalledPath(const std::string& relative);

}  // namespace linesim::models
