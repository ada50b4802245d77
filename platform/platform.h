#pragma once

#include <string>

namespace linesim::platform {

/// Whether the process's transcendental functions (sin, pow, atan2, expf, ...)
/// are the CPU-independent ones of deterministic_math.cc for every library
/// (true in the linesim executables), or glibc's CPU-dispatched libm (a
/// program or host that does not link them, e.g. an FMU master loading an
/// exported linesim FMU).
bool DeterministicMathBound();

/// "sleef 3.5 pure C (every library)" or "glibc libm (CPU-dispatched)".
std::string MathLibrary();

/// The CPU's model name (/proc/cpuinfo), "unknown" where it cannot be read.
std::string CpuModel();

/// The instruction-set extensions that libraries dispatch on, as the CPU
/// reports them: "sse4.2 avx avx2 fma avx512f" (those present).
std::string CpuFeatures();

}  // namespace linesim::platform
