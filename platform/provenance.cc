#include "platform/provenance.h"

#include <map>
#include <mutex>

#include "platform/build_info.h"
#include "platform/platform.h"

namespace linesim::platform {
namespace {

std::mutex& DispatchMutex() {
  static std::mutex m;
  return m;
}
std::map<std::string, std::string>& Dispatches() {
  static std::map<std::string, std::string> d;
  return d;
}

}  // namespace

std::string Version() { return build_info::kVersion; }
std::string Commit() { return build_info::Commit(); }
std::string Compiler() { return build_info::kCompiler; }
std::string BuildType() { return build_info::kBuildType; }

std::string VersionLine() {
  return "linesim " + Version() + " (commit " + Commit() + ", " + Compiler() + ", " + BuildType() +
         ")";
}

void RecordDispatch(const std::string& library, const std::string& choice) {
  const std::lock_guard<std::mutex> lock(DispatchMutex());
  Dispatches()[library] = choice;
}

nlohmann::json ProvenanceJson(const std::string& scenario_sha256, std::uint64_t seed) {
  nlohmann::json dispatch = nlohmann::json::object();
  dispatch["libm"] = MathLibrary();
  {
    const std::lock_guard<std::mutex> lock(DispatchMutex());
    for (const auto& [library, choice] : Dispatches()) dispatch[library] = choice;
  }
  return {{"linesim_version", Version()},
          {"commit", Commit()},
          {"compiler", Compiler()},
          {"build_type", BuildType()},
          {"cpu_model", CpuModel()},
          {"cpu_features", CpuFeatures()},
          {"dispatch", dispatch},
          {"scenario_sha256", scenario_sha256},
          {"seed", seed}};
}

}  // namespace linesim::platform
