#pragma once

#include <cstdint>
#include <string_view>

namespace linesim::cosim {

/// The seed of one unit's random generator, from the scenario seed and the
/// unit's name: independent of how many units there are, their order and the
/// thread count (FNV-1a of the name, mixed with splitmix64).
inline std::uint64_t DeriveSeed(std::uint64_t scenario_seed, std::string_view unit_name) {
  std::uint64_t h = 1469598103934665603ull;
  for (char c : unit_name) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  std::uint64_t z = scenario_seed + 0x9e3779b97f4a7c15ull * (h | 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace linesim::cosim
