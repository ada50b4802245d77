#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace linesim::fmu {

/// A private temporary folder (mkdtemp, mode 0700),
/// $TMPDIR/linesim-fmu-<pid>-XXXXXX, removed with everything in it when the
/// object goes, and also when the process ends otherwise: at exit(), and,
/// while no other handler is installed for them (a sanitizer's stays), on
/// a crash signal (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT: an FMU's
/// binary that crashes) and on SIGTERM / SIGINT (the app's stop handler calls RemoveLiveTempFolders before it
/// gives up on a second signal). The first folder of a process also sweeps
/// the folders of processes that are gone (SweepStaleTempFolders). Only
/// SIGKILL leaves a folder behind, until the next run's sweep.
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

/// Removes every TempFolder of this process that still exists; safe in a
/// signal handler (no allocation, system calls only).
void RemoveLiveTempFolders() noexcept;

/// Removes $TMPDIR/linesim-fmu-<pid>-* folders owned by this user whose
/// process no longer exists (kill(pid, 0) fails with ESRCH); folders of
/// live processes and of other users are left alone. Returns how many were
/// removed.
std::size_t SweepStaleTempFolders();

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
