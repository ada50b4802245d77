#include "mcap/crc32.h"

#include <zlib.h>

#include <algorithm>
#include <limits>

namespace linesim::mcap {

void Crc32::Update(std::string_view bytes) {
  // zlib takes a uInt length: feed larger inputs in pieces.
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  uLong crc = value_;
  while (left > 0) {
    const std::size_t n = std::min<std::size_t>(left, std::numeric_limits<uInt>::max());
    crc = ::crc32(crc, reinterpret_cast<const Bytef*>(p), static_cast<uInt>(n));
    p += n;
    left -= n;
  }
  value_ = static_cast<std::uint32_t>(crc);
}

std::uint32_t ComputeCrc32(std::string_view bytes) {
  Crc32 crc;
  crc.Update(bytes);
  return crc.Value();
}

}  // namespace linesim::mcap
