// The FMU's modelDescription.xml reader: the input is the XML text. A
// problem is an FmuError naming the file; nothing else may escape.
#include <cstddef>
#include <cstdint>
#include <string>

#include "units/fmu/model_description.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)linesim::fmu::ParseModelDescriptionText(text, "fuzz.fmu/modelDescription.xml");
  } catch (const linesim::fmu::FmuError&) {
  }
  return 0;
}
