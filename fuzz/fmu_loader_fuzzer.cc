// The FMU loader end to end: the input is an .fmu archive (zip). It is
// unpacked (entry names, links, sizes), its modelDescription.xml read and
// checked, the binary path built from the modelIdentifier and loaded, and
// an FMU that loads is set up, initialized, stepped and terminated. A
// problem is an FmuError (loading) or a UnitError / failed step (running);
// nothing else may escape, and no file may be left in $TMPDIR. Seeds: the
// test FMUs (tests/units/fmu/fmus, zipped by the build) and the issue 24
// classes (tools/fuzz.sh).
#include <cstddef>
#include <cstdint>
#include <string>

#include "cosim/unit.h"
#include "fuzz/fuzz_support.h"
#include "units/fmu/fmu_unit.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string file = linesim::fuzz::TempDir() + "/input.fmu";
  linesim::fuzz::WriteFile(file, data, size);
  try {
    linesim::fmu::FmuUnit unit("fuzz", file);
    unit.Setup(0, 10'000'000);
    unit.Initialize();
    for (int k = 0; k < 3; ++k) {
      if (unit.DoStep(k * 1'000'000, 1'000'000) != linesim::cosim::StepResult::kOk) break;
    }
    unit.Terminate();
  } catch (const linesim::fmu::FmuError&) {
  } catch (const linesim::cosim::UnitError&) {
  }
  return 0;
}
