#pragma once

#include <string>
#include <string_view>

namespace linesim::platform {

/// SHA-256 of `bytes` as 64 lowercase hex digits (OpenSSL's libcrypto).
std::string Sha256Hex(std::string_view bytes);

/// SHA-256 of a file's bytes; throws std::runtime_error naming the file when
/// it cannot be read.
std::string Sha256OfFile(const std::string& path);

}  // namespace linesim::platform
