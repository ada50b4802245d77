#include "models/models_dir.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

namespace linesim::models {

namespace fs = std::filesystem;

namespace {

struct CodeObject {
  fs::path dir;  // empty when unknown
  bool executable = true;
};

// The object that holds this code: the executable, or the shared object it
// is linked into (dladdr names the executable as it was started, which may
// be relative: /proc/self/exe is its real path).
CodeObject FindCodeObject() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&FindCodeObject), &info) != 0 && info.dli_fname != nullptr) {
    const fs::path object(info.dli_fname);
    std::error_code same_ec;
    if (object.is_absolute() && (ec || !fs::equivalent(object, exe, same_ec))) {
      return {object.parent_path(), false};
    }
  }
  return {ec ? fs::path() : exe.parent_path(), true};
}

}  // namespace

std::string CodeDir() { return FindCodeObject().dir.string(); }

std::string InstalledPath(const std::string& relative) {
  const std::string dir = CodeDir();
  if (dir.empty()) return {};
  std::error_code ec;
  const fs::path candidate = fs::weakly_canonical(fs::path(dir) / relative, ec);
  return !ec && fs::exists(candidate, ec) ? candidate.string() : std::string();
}

std::string ModelsDir() {
  if (const char* env = std::getenv("LINESIM_MODELS_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  // Found once: the files do not move while the program runs.
  static const std::string found = [] {
    // The installed layouts (the install rules of CMakeLists.txt; the
    // wheel of python/build_backend.py, whose models sit beside the native
    // module); a folder counts when it has robots.
    const std::vector<std::string> relatives =
        FindCodeObject().executable
            ? std::vector<std::string>{LINESIM_MODELS_FROM_BINDIR}
            : std::vector<std::string>{"models", LINESIM_MODELS_FROM_PYTHONDIR};
    for (const std::string& relative : relatives) {
      const std::string robots = InstalledPath(relative + "/robots");
      if (!robots.empty()) return fs::path(robots).parent_path().string();
    }
    return std::string(LINESIM_DEFAULT_MODELS_DIR);
  }();
  return found;
}

}  // namespace linesim::models
