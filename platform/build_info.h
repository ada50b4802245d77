#pragma once

#include <string>

// Written by CMake (build_info.cc.in at configure time, commit.cc at every
// build by write_commit.cmake).
namespace linesim::platform::build_info {

extern const char* const kVersion;
extern const char* const kCompiler;
extern const char* const kBuildType;
/// The git commit of the source tree at the last build.
std::string Commit();

}  // namespace linesim::platform::build_info
