#pragma once

#include <cstdint>
#include <string>

namespace linesim::fmu {

/// A private temporary folder (mkdtemp, mode 0700) removed with everything
/// in it when the object goes.
class TempFolder {
 public:
  TempFolder();
  ~TempFolder();
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// The most an FMU may unpack to (every file's size added up), so that a
/// crafted archive cannot fill the disk.
inline constexpr std::uint64_t kMaxUnpackedBytes = 4ULL << 30;

/// Unpacks the zip archive `fmu` into `folder` (which exists and is empty).
/// Refuses, with FmuError naming the archive and the entry, every entry
/// that could land outside the folder: a name with a `..` component, an
/// absolute name (/x, \x, C:), a backslash, a symbolic link; and an archive
/// that cannot be read or unpacks to more than kMaxUnpackedBytes. Files are
/// created new (O_EXCL | O_NOFOLLOW), never through an existing link.
void Unpack(const std::string& fmu, const std::string& folder);

}  // namespace linesim::fmu
