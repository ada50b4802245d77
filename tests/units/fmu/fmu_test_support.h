#pragma once

// What the FMU tests share: the paths of the FMUs the build zipped, and a
// temporary folder for archives made at run time.

#include <unistd.h>

#include <filesystem>
#include <string>

namespace linesim::fmu::test {

inline std::string Fmu(const std::string& name) {
  return std::string(LINESIM_TEST_FMU_DIR) + "/" + name + ".fmu";
}

/// A fresh folder for one test, removed afterwards.
class Scratch {
 public:
  explicit Scratch(const std::string& tag) {
    path_ = std::filesystem::temp_directory_path() /
            ("linesim-fmu-test-" + tag + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~Scratch() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace linesim::fmu::test
