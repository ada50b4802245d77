#pragma once

#include <cstdint>
#include <string_view>

/// CRC-32 as the MCAP specification uses it (the CRC of zlib, PNG and
/// Ethernet: reflected polynomial 0xEDB88320, initial value and final XOR
/// 0xFFFFFFFF). The CRC-32 of "123456789" is 0xCBF43926, the check value of
/// "CRC-32/ISO-HDLC" in the catalogue of parametrised CRC algorithms. zlib
/// computes it (its crc32 is several times faster than a byte-wise table,
/// and a run's MCAP log passes tens of megabytes through it).
namespace linesim::mcap {

/// A running CRC: Update it with the bytes in order, read Value() at the end.
class Crc32 {
 public:
  void Update(std::string_view bytes);
  std::uint32_t Value() const { return value_; }
  void Reset() { value_ = 0; }

 private:
  std::uint32_t value_ = 0;  // the CRC of the bytes so far (0 for none)
};

/// The CRC-32 of `bytes` in one call.
std::uint32_t ComputeCrc32(std::string_view bytes);

}  // namespace linesim::mcap
