#pragma once

#include <map>
#include <string>
#include <string_view>

namespace linesim::config {

/// The files a scenario's results depend on, recorded where they are read:
/// loader::LoadYamlFile records every YAML file (scenario, robot, scene,
/// motor and sensor models, route graphs), the fmu factory its FMU. A
/// caller that needs to know what a load read (a sweep's fingerprint, a
/// resumed sweep's check) opens a record around it; nothing is recorded
/// when none is open, so reading costs nothing more then.
///
/// Each file is keyed by its absolute path (lexically normal, so that a run
/// from another working folder names it the same) and holds the SHA-256 of
/// the bytes read, or kUnreadable.
class InputFileRecord {
 public:
  /// While it exists, every RecordInput* on this thread adds to it (and to
  /// the records open around it: records nest).
  InputFileRecord();
  ~InputFileRecord();
  InputFileRecord(const InputFileRecord&) = delete;
  InputFileRecord& operator=(const InputFileRecord&) = delete;

  /// Absolute path -> SHA-256 (64 hex digits) or kUnreadable.
  const std::map<std::string, std::string>& files() const { return files_; }

 private:
  friend void RecordInput(const std::string& path, std::string_view bytes);
  friend void RecordInputFile(const std::string& path);
  void Add(const std::string& path, const std::string& digest);

  std::map<std::string, std::string> files_;
  InputFileRecord* outer_ = nullptr;
};

/// What a record holds for a file that could not be read.
inline constexpr const char* kUnreadable = "unreadable";

/// Records `path` with the bytes the caller read from it (hashed only when
/// a record is open).
void RecordInput(const std::string& path, std::string_view bytes);
/// Records `path`, reading it to hash it (for files a library opens by
/// name, such as an FMU's zip archive). Never throws.
void RecordInputFile(const std::string& path);

/// The key a record uses for `path`.
std::string InputKey(const std::string& path);

/// The SHA-256 of the file at `path` now, or kUnreadable: what a record of
/// it would hold if it were read again.
std::string InputDigestNow(const std::string& path);

}  // namespace linesim::config
