#include "config/input_files.h"

#include <filesystem>
#include <stdexcept>

#include "platform/sha256.h"

namespace linesim::config {

namespace {

// The innermost record open on this thread: a load runs on one thread (a
// sweep's runs each on their own), so each sees only its own files.
thread_local InputFileRecord* current = nullptr;

}  // namespace

InputFileRecord::InputFileRecord() : outer_(current) { current = this; }

InputFileRecord::~InputFileRecord() { current = outer_; }

void InputFileRecord::Add(const std::string& path, const std::string& digest) {
  for (InputFileRecord* r = this; r; r = r->outer_) r->files_[path] = digest;
}

std::string InputKey(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  return (ec ? std::filesystem::path(path) : absolute).lexically_normal().string();
}

void RecordInput(const std::string& path, std::string_view bytes) {
  if (!current) return;
  current->Add(InputKey(path), platform::Sha256Hex(bytes));
}

std::string InputDigestNow(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return kUnreadable;
  try {
    return platform::Sha256OfFile(path);
  } catch (const std::exception&) {
    return kUnreadable;
  }
}

void RecordInputFile(const std::string& path) {
  if (!current) return;
  current->Add(InputKey(path), InputDigestNow(path));
}

}  // namespace linesim::config
