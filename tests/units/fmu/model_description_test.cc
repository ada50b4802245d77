// The model description reader (units/fmu/model_description.cc) on texts
// made in the test: the rules it enforces and the time it takes.
#include "units/fmu/model_description.h"

#include <gtest/gtest.h>

#include <string>

namespace linesim::fmu {
namespace {

// The error reading `text` ("" when it reads).
std::string ParseError(const std::string& text) {
  try {
    ParseModelDescriptionText(text, "md.xml");
  } catch (const FmuError& e) {
    return e.what();
  }
  return "";
}

std::string WithVersion(const std::string& version) {
  return "<?xml version=\"1.0\"?>\n<fmiModelDescription fmiVersion=\"" + version +
         "\" modelName=\"m\" guid=\"g\" instantiationToken=\"t\">\n"
         "  <CoSimulation modelIdentifier=\"m\"/>\n  <ModelVariables/>\n"
         "</fmiModelDescription>\n";
}

// Guards issue 24: fmiVersion was read by its prefix, so "2.0abc" (or 2.1,
// 3.7) was taken for 2.0 (3.0). The schemas fix the value: exactly "2.0" or
// "3.0", and anything else is refused with the rule named.
TEST(ModelDescription, FmiVersionMustBeExactlyASupportedOne) {
  EXPECT_EQ(ParseError(WithVersion("2.0")), "");
  EXPECT_EQ(ParseError(WithVersion("3.0")), "");
  for (const std::string bad : {"2.0abc", "2.1", "3.7", "3.0.1", " 2.0", "2", ""}) {
    const std::string e = ParseError(WithVersion(bad));
    EXPECT_NE(e.find("md.xml:2: unsupported FMI version '" + bad +
                     "': fmiVersion must be exactly \"2.0\" or \"3.0\""),
              std::string::npos)
        << bad << ": " << e;
  }
}

// An FMI 3.0 description with `n` Float64 variables, every fourth an input
// and every fourth an output depending on the input before it, one per line.
std::string Fmi3WithVariables(std::size_t n) {
  std::string vars, outputs;
  vars.reserve(n * 80);
  for (std::size_t i = 0; i < n; ++i) {
    const char* causality = i % 4 == 0 ? "input" : i % 4 == 1 ? "output" : "local";
    vars += "    <Float64 name=\"v" + std::to_string(i) + "\" valueReference=\"" +
            std::to_string(i) + "\" causality=\"" + causality + "\"/>\n";
    if (i % 4 == 1) {
      outputs += "    <Output valueReference=\"" + std::to_string(i) + "\" dependencies=\"" +
                 std::to_string(i - 1) + "\"/>\n";
    }
  }
  return "<?xml version=\"1.0\"?>\n<fmiModelDescription fmiVersion=\"3.0\" modelName=\"m\" "
         "instantiationToken=\"t\">\n  <CoSimulation modelIdentifier=\"m\"/>\n"
         "  <ModelVariables>\n" + vars + "  </ModelVariables>\n  <ModelStructure>\n" + outputs +
         "  </ModelStructure>\n</fmiModelDescription>\n";
}

// Guards issue 24's quadratic reading (5k variables 0.45 s, 40k 30 s,
// 200k more than 120 s: the line of each variable counted the newlines
// from the start, and each ModelStructure output searched the variables).
// 200k variables with 50k outputs now read in well under a second here (no
// timing assertion: the quadratic reader needed minutes, which ctest's
// 300 s timeout stops). The lines and dependencies stay right.
TEST(ModelDescription, ReadingIsLinearInTheVariables) {
  constexpr std::size_t n = 200'000;
  const std::string text = Fmi3WithVariables(n);
  const ModelDescription md = ParseModelDescriptionText(text, "md.xml");
  ASSERT_EQ(md.variables.size(), n);
  EXPECT_EQ(md.variables[0].line, 5);
  EXPECT_EQ(md.variables[n - 1].line, static_cast<int>(n) + 4);
  ASSERT_TRUE(md.variables[n - 3].dependencies);  // n - 3 = 1 (mod 4): an output
  EXPECT_EQ(*md.variables[n - 3].dependencies, std::vector<std::uint32_t>{n - 4});
}

// Guards the stated limit: a description with more than kMaxVariables
// variables is refused before any is read, naming the limit.
TEST(ModelDescription, MoreVariablesThanTheLimitAreRefused) {
  // Every element counts, so bare ones keep the text and the DOM small.
  std::string vars;
  const std::string one = "<v/>\n";
  vars.reserve((kMaxVariables + 1) * one.size());
  for (std::size_t i = 0; i <= kMaxVariables; ++i) vars += one;
  const std::string e = ParseError(
      "<?xml version=\"1.0\"?>\n<fmiModelDescription fmiVersion=\"3.0\" modelName=\"m\" "
      "instantiationToken=\"t\">\n  <CoSimulation modelIdentifier=\"m\"/>\n  <ModelVariables>\n" +
      vars + "  </ModelVariables>\n</fmiModelDescription>\n");
  EXPECT_NE(e.find("md.xml:" + std::to_string(kMaxVariables + 5) + ": more than " +
                   std::to_string(kMaxVariables) + " variables in <ModelVariables>"),
            std::string::npos)
      << e.substr(0, 300);
}

}  // namespace
}  // namespace linesim::fmu
