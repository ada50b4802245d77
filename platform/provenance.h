#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>

namespace linesim::platform {

/// The build: "0.1.0", the git commit it was built from ("unknown" outside a
/// checkout; "-dirty" appended when tracked files had changes), the compiler
/// and the build type.
std::string Version();
std::string Commit();
std::string Compiler();
std::string BuildType();
/// `linesim --version`: "linesim 0.1.0 (commit ..., GCC 12.2.0, Release)".
std::string VersionLine();

/// A library that chose its kernels by CPU at run time records its choice
/// (e.g. "embree" -> "avx2 kernels; ranges independent of them"), so that a
/// result names it. Thread safe; the last record per library wins.
void RecordDispatch(const std::string& library, const std::string& choice);

/// What a result depends on beyond its inputs, as summary.json records it:
/// version, commit, compiler, build type, CPU model and features, the
/// math library and every recorded dispatch, the scenario's SHA-256 (after
/// --set) and the seed.
nlohmann::json ProvenanceJson(const std::string& scenario_sha256, std::uint64_t seed);

}  // namespace linesim::platform
