// The project's test FMUs (fmus/*.c, fmus/*.xml) against the standards, so
// that any other master can run them: their model descriptions follow the
// schemas' rules (fmi_schema_rules.h), their binaries export every function
// the standard requires, and what they declare they serve (the independent
// time, a Binary input). Guards issue 37: they lacked functions FMI 2.0.4
// section 2.3 and FMI 3.0.2 section 2.5 require, used the unit "s" without
// UnitDefinitions, declared `time` and refused to return it, and had a
// Binary input without fmi3GetBinary.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "tests/units/fmu/fmi_schema_rules.h"
#include "units/fmu/fmi_api.h"
#include "units/fmu/model_description.h"

namespace linesim::fmu {
namespace {

namespace fs = std::filesystem;

struct TestFmu {
  std::string name;
  std::string xml;  // modelDescription.xml's text
  std::string so;   // the built binary
};

std::vector<TestFmu> TestFmus() {
  std::vector<TestFmu> out;
  for (const auto& e : fs::directory_iterator(LINESIM_SOURCE_DIR "/tests/units/fmu/fmus")) {
    if (e.path().extension() != ".xml") continue;
    const std::string name = e.path().stem().string();
    std::ifstream in(e.path());
    std::stringstream text;
    text << in.rdbuf();
    out.push_back(
        {name, text.str(),
         std::string(LINESIM_TEST_FMU_DIR) + "/fmu_build/" + name + "/lib/" + name + ".so"});
  }
  return out;
}

TEST(TestFmus, ModelDescriptionsFollowTheSchemaRules) {
  const auto fmus = TestFmus();
  ASSERT_GE(fmus.size(), 9u);
  for (const TestFmu& fmu : fmus) {
    for (const std::string& p : test::SchemaProblems(fmu.xml))
      ADD_FAILURE() << fmu.name << ": " << p;
  }
  // The checker sees what it guards against: a unit without its
  // definition, a 32-bit integer beyond 32 bits.
  const std::string bad =
      "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"m\" instantiationToken=\"t\">"
      "<CoSimulation modelIdentifier=\"m\"/><ModelVariables>"
      "<Float64 name=\"x\" valueReference=\"0\" causality=\"output\" unit=\"s\"/>"
      "<Int32 name=\"seed\" valueReference=\"1\" causality=\"parameter\" variability=\"fixed\" "
      "start=\"-1\" min=\"-1\" max=\"4294967295\"/></ModelVariables>"
      "<ModelStructure><Output valueReference=\"0\"/></ModelStructure></fmiModelDescription>";
  const auto problems = test::SchemaProblems(bad);
  ASSERT_EQ(problems.size(), 2u) << ::testing::PrintToString(problems);
  EXPECT_NE(problems[0].find("unit 's' is not in UnitDefinitions"), std::string::npos);
  EXPECT_NE(problems[1].find("max=\"4294967295\" is outside"), std::string::npos);
}

// FMI 2.0.4 sections 2.1 and 4.2: every co-simulation binary exports all
// of these, "even if they are not used/supported" (then they return
// fmi2Error). FMI 3.0.2 section 2.5: all common functions and those of the
// interface type, even for capabilities the FMU lacks.
const char* const kFmi2Functions[] = {"fmi2GetTypesPlatform",
                                      "fmi2GetVersion",
                                      "fmi2SetDebugLogging",
                                      "fmi2Instantiate",
                                      "fmi2FreeInstance",
                                      "fmi2SetupExperiment",
                                      "fmi2EnterInitializationMode",
                                      "fmi2ExitInitializationMode",
                                      "fmi2Terminate",
                                      "fmi2Reset",
                                      "fmi2GetReal",
                                      "fmi2GetInteger",
                                      "fmi2GetBoolean",
                                      "fmi2GetString",
                                      "fmi2SetReal",
                                      "fmi2SetInteger",
                                      "fmi2SetBoolean",
                                      "fmi2SetString",
                                      "fmi2GetFMUstate",
                                      "fmi2SetFMUstate",
                                      "fmi2FreeFMUstate",
                                      "fmi2SerializedFMUstateSize",
                                      "fmi2SerializeFMUstate",
                                      "fmi2DeSerializeFMUstate",
                                      "fmi2GetDirectionalDerivative",
                                      "fmi2SetRealInputDerivatives",
                                      "fmi2GetRealOutputDerivatives",
                                      "fmi2DoStep",
                                      "fmi2CancelStep",
                                      "fmi2GetStatus",
                                      "fmi2GetRealStatus",
                                      "fmi2GetIntegerStatus",
                                      "fmi2GetBooleanStatus",
                                      "fmi2GetStringStatus"};
const char* const kFmi3Functions[] = {"fmi3GetVersion",
                                      "fmi3SetDebugLogging",
                                      "fmi3InstantiateCoSimulation",
                                      "fmi3FreeInstance",
                                      "fmi3EnterInitializationMode",
                                      "fmi3ExitInitializationMode",
                                      "fmi3EnterEventMode",
                                      "fmi3Terminate",
                                      "fmi3Reset",
                                      "fmi3GetFloat32",
                                      "fmi3GetFloat64",
                                      "fmi3GetInt8",
                                      "fmi3GetUInt8",
                                      "fmi3GetInt16",
                                      "fmi3GetUInt16",
                                      "fmi3GetInt32",
                                      "fmi3GetUInt32",
                                      "fmi3GetInt64",
                                      "fmi3GetUInt64",
                                      "fmi3GetBoolean",
                                      "fmi3GetString",
                                      "fmi3GetBinary",
                                      "fmi3GetClock",
                                      "fmi3SetFloat32",
                                      "fmi3SetFloat64",
                                      "fmi3SetInt8",
                                      "fmi3SetUInt8",
                                      "fmi3SetInt16",
                                      "fmi3SetUInt16",
                                      "fmi3SetInt32",
                                      "fmi3SetUInt32",
                                      "fmi3SetInt64",
                                      "fmi3SetUInt64",
                                      "fmi3SetBoolean",
                                      "fmi3SetString",
                                      "fmi3SetBinary",
                                      "fmi3SetClock",
                                      "fmi3GetNumberOfVariableDependencies",
                                      "fmi3GetVariableDependencies",
                                      "fmi3GetFMUState",
                                      "fmi3SetFMUState",
                                      "fmi3FreeFMUState",
                                      "fmi3SerializedFMUStateSize",
                                      "fmi3SerializeFMUState",
                                      "fmi3DeserializeFMUState",
                                      "fmi3GetDirectionalDerivative",
                                      "fmi3GetAdjointDerivative",
                                      "fmi3EnterConfigurationMode",
                                      "fmi3ExitConfigurationMode",
                                      "fmi3GetIntervalDecimal",
                                      "fmi3GetIntervalFraction",
                                      "fmi3GetShiftDecimal",
                                      "fmi3GetShiftFraction",
                                      "fmi3SetIntervalDecimal",
                                      "fmi3SetIntervalFraction",
                                      "fmi3SetShiftDecimal",
                                      "fmi3SetShiftFraction",
                                      "fmi3EvaluateDiscreteStates",
                                      "fmi3UpdateDiscreteStates",
                                      "fmi3EnterStepMode",
                                      "fmi3GetOutputDerivatives",
                                      "fmi3DoStep"};

struct Library {
  explicit Library(const std::string& so) : handle(dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL)) {}
  ~Library() {
    if (handle) dlclose(handle);
  }
  template <typename F>
  F Get(const char* name) const {
    return reinterpret_cast<F>(dlsym(handle, name));
  }
  void* handle;
};

TEST(TestFmus, BinariesExportEveryFunctionTheStandardRequires) {
  for (const TestFmu& fmu : TestFmus()) {
    const Library lib(fmu.so);
    ASSERT_NE(lib.handle, nullptr) << fmu.so << ": " << dlerror();
    const bool v3 = fmu.xml.find("fmiVersion=\"3.0\"") != std::string::npos;
    if (v3) {
      for (const char* f : kFmi3Functions)
        EXPECT_NE(dlsym(lib.handle, f), nullptr) << fmu.name << ": " << f;
    } else {
      for (const char* f : kFmi2Functions)
        EXPECT_NE(dlsym(lib.handle, f), nullptr) << fmu.name << ": " << f;
    }
  }
}

void Log3(void*, fmi3::Status, const char*, const char*) {}

// What a master that reads `time` (fmusim records it) and a Binary output
// gets: each FMU with an independent variable returns the start time after
// initialization, and types3 its Binary output (the input's start "foo").
TEST(TestFmus, TheIndependentTimeAndTheBinaryOutputCanBeRead) {
  for (const TestFmu& fmu : TestFmus()) {
    const ModelDescription md = ParseModelDescriptionText(fmu.xml, fmu.name);
    std::optional<std::uint32_t> time_vr;
    for (const auto& v : md.variables) {
      if (v.causality == "independent") time_vr = v.value_reference;
    }
    if (!time_vr || md.fmi_major != 3) continue;  // dahlquist (FMI 2.0): below
    const Library lib(fmu.so);
    ASSERT_NE(lib.handle, nullptr) << fmu.so;
    const auto instantiate =
        lib.Get<fmi3::InstantiateCoSimulationTYPE>("fmi3InstantiateCoSimulation");
    void* c = instantiate("t", md.token.c_str(), "", false, false, false, false, nullptr, 0,
                          nullptr, &Log3, nullptr);
    ASSERT_NE(c, nullptr) << fmu.name;
    EXPECT_EQ(lib.Get<fmi3::EnterInitializationModeTYPE>("fmi3EnterInitializationMode")(
                  c, false, 0.0, 0.25, false, 0.0),
              0);
    EXPECT_EQ(lib.Get<fmi3::ExitInitializationModeTYPE>("fmi3ExitInitializationMode")(c), 0);
    double t = -1;
    EXPECT_EQ(lib.Get<fmi3::GetFloat64TYPE>("fmi3GetFloat64")(c, &*time_vr, 1, &t, 1), 0)
        << fmu.name << " refuses its time";
    EXPECT_EQ(t, 0.25) << fmu.name;
    lib.Get<fmi3::FreeInstanceTYPE>("fmi3FreeInstance")(c);
  }
  // types3's Binary output, the copy of its Binary input's start "foo".
  const Library lib(std::string(LINESIM_TEST_FMU_DIR) + "/fmu_build/types3/lib/types3.so");
  ASSERT_NE(lib.handle, nullptr);
  void* c = lib.Get<fmi3::InstantiateCoSimulationTYPE>("fmi3InstantiateCoSimulation")(
      "t", "{linesim-test-types-3}", "", false, false, false, false, nullptr, 0, nullptr, &Log3,
      nullptr);
  ASSERT_NE(c, nullptr);
  ASSERT_EQ(lib.Get<fmi3::EnterInitializationModeTYPE>("fmi3EnterInitializationMode")(
                c, false, 0.0, 0.0, false, 0.0),
            0);
  using GetBinary = int (*)(void*, const std::uint32_t[], std::size_t, std::size_t[],
                            const std::uint8_t*[], std::size_t);
  const std::uint32_t vr = 491;
  std::size_t size = 0;
  const std::uint8_t* bytes = nullptr;
  ASSERT_EQ(lib.Get<GetBinary>("fmi3GetBinary")(c, &vr, 1, &size, &bytes, 1), 0);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(bytes), size), "foo");
  lib.Get<fmi3::FreeInstanceTYPE>("fmi3FreeInstance")(c);
}

}  // namespace
}  // namespace linesim::fmu
