// The model description reader (units/fmu/model_description.cc) on texts
// made in the test: the rules it enforces and the time it takes.
#include "units/fmu/model_description.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
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
// (with its start value, which inputs need) and every fourth an output depending on the input
// before it, one per line.
std::string Fmi3WithVariables(std::size_t n) {
  std::string vars, outputs;
  vars.reserve(n * 80);
  for (std::size_t i = 0; i < n; ++i) {
    const char* causality = i % 4 == 0 ? "input" : i % 4 == 1 ? "output" : "local";
    vars += "    <Float64 name=\"v" + std::to_string(i) + "\" valueReference=\"" +
            std::to_string(i) + "\" causality=\"" + causality + "\"" +
            (i % 4 == 0 ? " start=\"0\"" : "") + "/>\n";
    if (i % 4 == 1) {
      outputs += "    <Output valueReference=\"" + std::to_string(i) + "\" dependencies=\"" +
                 std::to_string(i - 1) + "\"/>\n";
    }
  }
  return "<?xml version=\"1.0\"?>\n<fmiModelDescription fmiVersion=\"3.0\" modelName=\"m\" "
         "instantiationToken=\"t\">\n  <CoSimulation modelIdentifier=\"m\"/>\n"
         "  <ModelVariables>\n" +
         vars + "  </ModelVariables>\n  <ModelStructure>\n" + outputs +
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

// FMI 2.0 and 3.0 descriptions with the given variables (and FMI 2.0
// outputs / FMI 3.0 structure).
std::string Fmi2(const std::string& types, const std::string& vars,
                 const std::string& outputs = "") {
  return "<?xml version=\"1.0\"?>\n<fmiModelDescription fmiVersion=\"2.0\" modelName=\"m\" "
         "guid=\"g\">\n  <CoSimulation modelIdentifier=\"m\"/>\n  <TypeDefinitions>" +
         types + "</TypeDefinitions>\n  <ModelVariables>\n" + vars +
         "  </ModelVariables>\n  <ModelStructure><Outputs>" + outputs +
         "</Outputs></ModelStructure>\n</fmiModelDescription>\n";
}
std::string Fmi3(const std::string& types, const std::string& vars,
                 const std::string& structure = "") {
  return "<?xml version=\"1.0\"?>\n<fmiModelDescription fmiVersion=\"3.0\" modelName=\"m\" "
         "instantiationToken=\"t\">\n  <CoSimulation modelIdentifier=\"m\"/>\n  <TypeDefinitions>" +
         types + "</TypeDefinitions>\n  <ModelVariables>\n" + vars +
         "  </ModelVariables>\n  <ModelStructure>" + structure +
         "</ModelStructure>\n</fmiModelDescription>\n";
}
std::string Sv(const std::string& name, int vr, const std::string& causality,
               const std::string& body = "<Real/>", const std::string& variability = "") {
  return "    <ScalarVariable name=\"" + name + "\" valueReference=\"" + std::to_string(vr) +
         "\" causality=\"" + causality + "\"" +
         (variability.empty() ? "" : " variability=\"" + variability + "\"") + ">" + body +
         "</ScalarVariable>\n";
}

// Guards issue 24: rules of the standards that the schemas cannot express
// were not checked, and such an FMU ran with wrong numbers. Each is refused
// with the rule named; the lawful neighbour of each case reads.
TEST(ModelDescription, RulesTheSchemaCannotExpressAreEnforced) {
  const std::string p1 = Sv("a", 1, "parameter", "<Real start=\"1\"/>", "fixed");
  const std::string p2 = Sv("b", 1, "parameter", "<Real start=\"2\"/>", "fixed");
  const std::string in = Sv("u", 2, "input", "<Real start=\"0\"/>");
  const std::string out = Sv("y", 2, "output");
  const std::string out3 = Sv("y", 3, "output");
  // FMI 2.0 aliases: two parameters on one reference; an input on an output's.
  EXPECT_NE(ParseError(Fmi2("", p1 + p2)).find("two variables set from outside share a value"),
            std::string::npos)
      << ParseError(Fmi2("", p1 + p2));
  EXPECT_NE(ParseError(Fmi2("", in + out, "<Unknown index=\"2\"/>"))
                .find("an input cannot alias a computed variable"),
            std::string::npos)
      << ParseError(Fmi2("", in + out, "<Unknown index=\"2\"/>"));
  // Another base type on the same reference is no alias; an output alias of
  // a local is lawful.
  EXPECT_EQ(ParseError(Fmi2("", p1 + Sv("n", 1, "parameter", "<Integer start=\"1\"/>", "fixed"))),
            "");
  EXPECT_EQ(ParseError(Fmi2("", in + out3 + Sv("l", 3, "local"), "<Unknown index=\"2\"/>")), "");
  // FMI 3.0: a valueReference is a variable's own.
  const std::string f1 = "    <Float64 name=\"a\" valueReference=\"1\" causality=\"local\"/>\n";
  const std::string f2 = "    <Int32 name=\"b\" valueReference=\"1\" causality=\"local\"/>\n";
  EXPECT_NE(ParseError(Fmi3("", f1 + f2)).find("every variable has a valueReference of its own"),
            std::string::npos)
      << ParseError(Fmi3("", f1 + f2));
  // ModelStructure: indices in range, naming outputs.
  EXPECT_NE(ParseError(Fmi2("", in + out3, "<Unknown index=\"7\"/>"))
                .find("output index 7 names no variable"),
            std::string::npos);
  EXPECT_NE(ParseError(Fmi2("", in + out3, "<Unknown index=\"1\"/>")).find("is 'u', a input"),
            std::string::npos)
      << ParseError(Fmi2("", in + out3, "<Unknown index=\"1\"/>"));
  EXPECT_NE(ParseError(Fmi2("", in + out3, "<Unknown index=\"2\" dependencies=\"9\"/>"))
                .find("dependency index 9 names no variable"),
            std::string::npos);
  const std::string o3 = "    <Float64 name=\"y\" valueReference=\"2\" causality=\"output\"/>\n";
  EXPECT_NE(ParseError(Fmi3("", f1 + o3, "<Output valueReference=\"2\" dependencies=\"8\"/>"))
                .find("depends on valueReference 8, which names no variable"),
            std::string::npos);
  EXPECT_NE(ParseError(Fmi3("", f1 + o3, "<Output valueReference=\"1\"/>"))
                .find("only outputs are listed"),
            std::string::npos);
  EXPECT_NE(ParseError(Fmi3("", f1 + o3, "<InitialUnknown valueReference=\"5\"/>"))
                .find("names no variable"),
            std::string::npos);
  EXPECT_EQ(ParseError(Fmi3("", f1 + o3, "<Output valueReference=\"2\" dependencies=\"1\"/>")), "");
  // Declared types exist and fit; start values within [min, max]; a NaN
  // start of a value linesim gives the FMU; an enumeration start an item.
  EXPECT_NE(ParseError(Fmi2("", Sv("a", 1, "local", "<Real declaredType=\"T\"/>")))
                .find("declaredType 'T' is not in <TypeDefinitions>"),
            std::string::npos);
  const std::string enum2 =
      "<SimpleType name=\"E\"><Enumeration><Item name=\"a\" value=\"1\"/>"
      "<Item name=\"b\" value=\"4\"/></Enumeration></SimpleType>";
  EXPECT_NE(ParseError(Fmi2(enum2, Sv("a", 1, "local", "<Real declaredType=\"E\"/>")))
                .find("is a Enumeration, not a type for this variable"),
            std::string::npos)
      << ParseError(Fmi2(enum2, Sv("a", 1, "local", "<Real declaredType=\"E\"/>")));
  EXPECT_NE(ParseError(Fmi2("", Sv("a", 1, "parameter", "<Real start=\"5\" min=\"0\" max=\"2\"/>",
                                   "fixed")))
                .find("start value 5 is outside [0, 2] (FMI: min <= start <= max)"),
            std::string::npos);
  EXPECT_NE(ParseError(Fmi2("", Sv("a", 1, "parameter", "<Real start=\"NaN\"/>", "fixed")))
                .find("start value NaN"),
            std::string::npos);
  EXPECT_NE(
      ParseError(Fmi2(enum2, Sv("a", 1, "input", "<Enumeration declaredType=\"E\" start=\"3\"/>")))
          .find("start value 3 is no item of enumeration 'E'"),
      std::string::npos);
  EXPECT_EQ(
      ParseError(Fmi2(enum2, Sv("a", 1, "input", "<Enumeration declaredType=\"E\" start=\"4\"/>"))),
      "");
  EXPECT_NE(
      ParseError(
          Fmi3("",
               "    <Int8 name=\"a\" valueReference=\"1\" causality=\"input\" start=\"300\"/>\n"))
          .find("start value '300' is not a Int8"),
      std::string::npos);
}
// `text` with `units` as its <UnitDefinitions>, before <TypeDefinitions>
// (where the schemas put it).
std::string WithUnits(std::string text, const std::string& units) {
  const std::size_t at = text.find("  <TypeDefinitions>");
  text.insert(at, "  <UnitDefinitions>" + units + "</UnitDefinitions>\n");
  return text;
}

// Guards issue 24: a parameter or input without a start value was read and
// linesim gave the FMU 0 for it, a value the FMU never declared. The
// standards require one (FMI 2.0.4 section 2.2.7, FMI 3.0 section 2.4.7.5:
// a parameter's initial is exact; initial exact or approx, or causality
// input, needs a start): refused naming the rule. An output, a local and a
// calculated parameter need none.
TEST(ModelDescription, ParameterOrInputWithoutStartIsRefused) {
  for (const char* causality : {"parameter", "input"}) {
    SCOPED_TRACE(causality);
    const std::string e =
        ParseError(Fmi2("", Sv("a", 1, causality, "<Real/>", causality[0] == 'p' ? "fixed" : "")));
    EXPECT_NE(e.find(std::string("variable 'a': ") + causality +
                     " without a start value (FMI: a parameter or input must have one)"),
              std::string::npos)
        << e;
  }
  EXPECT_NE(ParseError(Fmi2("", Sv("n", 1, "parameter", "<Integer/>", "tunable")))
                .find("parameter without a start value"),
            std::string::npos);
  EXPECT_NE(ParseError(Fmi3("",
                            "    <Float64 name=\"a\" valueReference=\"1\" "
                            "causality=\"parameter\" variability=\"fixed\"/>\n"))
                .find("parameter without a start value"),
            std::string::npos);
  EXPECT_NE(ParseError(Fmi3("",
                            "    <Int32 name=\"s\" valueReference=\"1\" "
                            "causality=\"structuralParameter\" variability=\"fixed\"/>\n"))
                .find("structuralParameter without a start value"),
            std::string::npos);
  EXPECT_EQ(ParseError(Fmi2("",
                            Sv("y", 1, "output") + Sv("l", 2, "local") +
                                Sv("c", 3, "calculatedParameter", "<Real/>", "fixed"),
                            "<Unknown index=\"1\"/>")),
            "");
}

// Guards issue 24: a variable's unit that its FMU's <UnitDefinitions> does
// not define was read as if it were an SI expression. The unit attribute
// references a unit definition (FMI 2.0.4 section 2.2.2; FMI 3.0 likewise):
// with UnitDefinitions present, a unit not among them is refused, naming
// it, on the variable and through its declared type. Without
// UnitDefinitions the FMU is read and the name understood as an SI
// expression (README, FMUs as units).
TEST(ModelDescription, AUnitMustBeInUnitDefinitionsWhenTheFmuHasThem) {
  const std::string units = "<Unit name=\"m\"><BaseUnit m=\"1\"/></Unit>";
  const std::string in_m = Sv("u", 1, "input", "<Real unit=\"m\" start=\"0\"/>");
  const std::string in_s = Sv("v", 2, "input", "<Real unit=\"s\" start=\"0\"/>");
  EXPECT_EQ(ParseError(WithUnits(Fmi2("", in_m), units)), "");
  const std::string e = ParseError(WithUnits(Fmi2("", in_m + in_s), units));
  EXPECT_NE(e.find("variable 'v': unit 's' is not in <UnitDefinitions>"), std::string::npos) << e;
  const std::string type = "<SimpleType name=\"T\"><Real unit=\"m/s\"/></SimpleType>";
  const std::string typed = Sv("w", 3, "input", "<Real declaredType=\"T\" start=\"0\"/>");
  EXPECT_NE(ParseError(WithUnits(Fmi2(type, in_m + typed), units))
                .find("variable 'w': unit 'm/s' is not in <UnitDefinitions>"),
            std::string::npos);
  const std::string f3 =
      "    <Float64 name=\"y\" valueReference=\"1\" causality=\"output\" "
      "unit=\"rad\"/>\n";
  const std::string out3 = "<Output valueReference=\"1\"/>";
  EXPECT_NE(ParseError(WithUnits(Fmi3("", f3, out3), units))
                .find("variable 'y': unit 'rad' is not in <UnitDefinitions>"),
            std::string::npos);
  // No UnitDefinitions: the names are read as SI expressions.
  EXPECT_EQ(ParseError(Fmi2("", in_m + in_s)), "");
  EXPECT_EQ(ParseError(Fmi3("", f3, out3)), "");
}

// Guards issue 24: every file read has a size limit checked before
// parsing. A (sparse) model description one byte above
// kMaxModelDescriptionBytes is refused naming the file and the limit.
TEST(ModelDescription, AFileAboveTheSizeLimitIsRefusedBeforeReading) {
  const std::string file = ::testing::TempDir() + "md_size_" + std::to_string(::getpid()) + ".xml";
  { std::ofstream(file) << "<"; }
  std::filesystem::resize_file(file, kMaxModelDescriptionBytes + 1);
  try {
    ParseModelDescription(file);
    ADD_FAILURE() << "read a model description above the limit";
  } catch (const FmuError& e) {
    EXPECT_NE(std::string(e.what()).find(file + ": the model description is 134217729 bytes, more "
                                                "than the 128 MiB linesim reads"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove(file);
}
}  // namespace
}  // namespace linesim::fmu
