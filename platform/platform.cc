#include "platform/platform.h"

#include <dlfcn.h>
#include <sleef.h>

#include <fstream>
#include <initializer_list>
#include <string>

namespace linesim::platform {

bool DeterministicMathBound() {
  // Each function must resolve, in the global scope that every shared library
  // binds through, to the definition in the executable rather than libm's.
  for (const char* name : {"sin", "sincos", "atan2", "pow", "exp", "log", "expf", "logf"}) {
    void* address = dlsym(RTLD_DEFAULT, name);
    Dl_info info{};
    if (address == nullptr || dladdr(address, &info) == 0 || info.dli_fname == nullptr) {
      return false;
    }
    const std::string file = info.dli_fname;
    if (file.find("libm.so") != std::string::npos) return false;
  }
  return true;
}

std::string MathLibrary() {
  if (!DeterministicMathBound()) return "glibc libm (CPU-dispatched)";
  return "sleef " + std::to_string(SLEEF_VERSION_MAJOR) + "." +
         std::to_string(SLEEF_VERSION_MINOR) + "." + std::to_string(SLEEF_VERSION_PATCHLEVEL) +
         " pure C, 1 to 3.5 ulp (every library)";
}

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) break;
    const auto first = line.find_first_not_of(" \t", colon + 1);
    return first == std::string::npos ? "unknown" : line.substr(first);
  }
  return "unknown";
}

std::string CpuFeatures() {
  std::string out;
  auto add = [&out](bool present, const char* name) {
    if (!present) return;
    if (!out.empty()) out += ' ';
    out += name;
  };
  __builtin_cpu_init();
  add(__builtin_cpu_supports("sse4.2"), "sse4.2");
  add(__builtin_cpu_supports("avx"), "avx");
  add(__builtin_cpu_supports("avx2"), "avx2");
  add(__builtin_cpu_supports("fma"), "fma");
  add(__builtin_cpu_supports("avx512f"), "avx512f");
  return out;
}

}  // namespace linesim::platform
