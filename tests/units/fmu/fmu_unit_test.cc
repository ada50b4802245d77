// The test FMUs (tests/units/fmu/fmus/*.c, zipped by CMake) through the fmu
// unit, each against its analytic result.
#include "units/fmu/fmu_unit.h"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>

#include "tests/units/fmu/fmu_test_support.h"
#include "tests/units/fmu/fmu_test_zip.h"

namespace linesim::fmu {
namespace {

using cosim::Causality;
using cosim::StepResult;
using cosim::TimeNs;
using cosim::VarType;
using test::Fmu;

constexpr TimeNs kMs = 1'000'000;

const cosim::VariableInfo& Info(const cosim::Unit& u, const std::string& name) {
  const auto ref = u.variables().Find(name);
  EXPECT_TRUE(ref) << name;
  return u.variables().info(*ref);
}
double Real(const cosim::Unit& u, const std::string& name) {
  return u.variables().GetReal(*u.variables().Find(name));
}
void SetReal(cosim::Unit& u, const std::string& name, double v) {
  u.variables().SetReal(*u.variables().Find(name), v);
}
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Guards the mapping of an FMI 2.0 model description: names made
// identifiers, causality, units from the variable, its declaredType and
// UnitDefinitions ("s-1" with base unit s^-1 is linesim's "1/s"), the
// independent time left out, and ModelStructure's (empty) dependencies.
TEST(FmuUnit, MapsTheDahlquistModelDescription) {
  FmuUnit u("d", Fmu("dahlquist"));
  EXPECT_EQ(u.description().fmi_major, 2);
  EXPECT_EQ(u.description().generation_tool, "linesim tests (hand-written C)");
  EXPECT_TRUE(u.description().can_serialize_state);
  ASSERT_TRUE(u.description().default_step);
  EXPECT_EQ(*u.description().default_step, 0.01);
  EXPECT_EQ(Info(u, "x").causality, Causality::kOutput);
  EXPECT_EQ(Info(u, "x").unit, "m");  // declaredType Position
  EXPECT_TRUE(Info(u, "x").depends_on.empty());
  EXPECT_EQ(Info(u, "k").causality, Causality::kParameter);
  EXPECT_EQ(Info(u, "k").unit, "1/s");
  EXPECT_EQ(Info(u, "k").variability, cosim::Variability::kFixed);
  EXPECT_EQ(Info(u, "x0").unit, "m");
  EXPECT_EQ(Info(u, "u").causality, Causality::kInput);
  EXPECT_EQ(Info(u, "u").unit, "m/s");
  EXPECT_EQ(Info(u, "der_x_").causality, Causality::kLocal);
  EXPECT_NE(Info(u, "der_x_").description.find("FMI 'der(x)'"), std::string::npos);
  EXPECT_FALSE(u.variables().Find("time"));
  EXPECT_EQ(Real(u, "k"), 1.0);  // start values
  EXPECT_EQ(Real(u, "x0"), 1.0);
}

// x' = -k x stepped exactly: after n steps of h, x = x0 e^{-k t_n} to
// rounding (analytic solution of Dahlquist's test equation); and the same
// bits as the per-step recurrence x <- x e^{-k h}, which shows that every
// step got exactly h and the time start + k h.
TEST(FmuUnit, DahlquistFollowsTheClosedForm) {
  FmuUnit u("d", Fmu("dahlquist"));
  const double k = 2.0, x0 = 1.5;
  SetReal(u, "k", k);
  SetReal(u, "x0", x0);
  const TimeNs h = 10 * kMs;
  u.Setup(0, 2000 * kMs);
  u.Initialize();
  EXPECT_EQ(Real(u, "x"), x0);
  double recurrence = x0;
  const double factor = std::exp(-k * cosim::NsToSeconds(h));
  for (int n = 0; n < 200; ++n) {
    ASSERT_EQ(u.DoStep(n * h, h), StepResult::kOk) << u.last_error();
    recurrence *= factor;
    const double t = cosim::NsToSeconds((n + 1) * h);
    const double exact = x0 * std::exp(-k * t);
    ASSERT_TRUE(SameBits(Real(u, "x"), recurrence)) << n;
    ASSERT_NEAR(Real(u, "x"), exact, 1e-13 * exact) << "t = " << t;
  }
  EXPECT_NEAR(Real(u, "der_x_"), -k * Real(u, "x"), 1e-15);
  u.Terminate();
  // The FMU's log reached the unit.
  ASSERT_FALSE(u.messages().empty());
  EXPECT_NE(u.messages()[0].find("instantiated {linesim-test-dahlquist-2}"), std::string::npos)
      << u.messages()[0];
}

// With a constant input u: x(t) = u/k + (x0 - u/k) e^{-k t} (the closed form
// of x' = -k x + u).
TEST(FmuUnit, DahlquistWithAConstantInput) {
  FmuUnit u("d", Fmu("dahlquist"));
  const double k = 0.5, x0 = -1.0, in = 0.3;
  SetReal(u, "k", k);
  SetReal(u, "x0", x0);
  u.Setup(0, 1000 * kMs);
  u.Initialize();
  SetReal(u, "u", in);
  for (int n = 0; n < 100; ++n) ASSERT_EQ(u.DoStep(n * 7 * kMs, 7 * kMs), StepResult::kOk);
  const double t = 0.7;
  const double exact = in / k + (x0 - in / k) * std::exp(-k * t);
  EXPECT_NEAR(Real(u, "x"), exact, 1e-14);
}

// Save, run, restore, run again: the same bits (the FMU state serialized
// into the UnitState, canSerializeFMUstate); and the state restores into a
// second unit of the same FMU, which then continues identically.
TEST(FmuUnit, SaveAndRestoreContinueBitForBit) {
  FmuUnit a("d", Fmu("dahlquist"));
  SetReal(a, "k", 3.0);
  a.Setup(0, 1000 * kMs);
  a.Initialize();
  SetReal(a, "u", 0.25);
  for (int n = 0; n < 30; ++n) ASSERT_EQ(a.DoStep(n * kMs, kMs), StepResult::kOk);
  const cosim::UnitState saved = a.SaveState();
  ASSERT_EQ(saved.strings.size(), 1u);  // the serialized FMU state
  std::vector<double> first;
  for (int n = 30; n < 60; ++n) {
    SetReal(a, "u", 0.01 * n);
    ASSERT_EQ(a.DoStep(n * kMs, kMs), StepResult::kOk);
    first.push_back(Real(a, "x"));
  }
  a.RestoreState(saved);
  FmuUnit b("d", Fmu("dahlquist"));
  b.Setup(0, 1000 * kMs);
  b.Initialize();
  b.RestoreState(saved);
  EXPECT_EQ(Real(b, "k"), 3.0);
  for (int n = 30; n < 60; ++n) {
    SetReal(a, "u", 0.01 * n);
    SetReal(b, "u", 0.01 * n);
    ASSERT_EQ(a.DoStep(n * kMs, kMs), StepResult::kOk);
    ASSERT_EQ(b.DoStep(n * kMs, kMs), StepResult::kOk);
    EXPECT_TRUE(SameBits(Real(a, "x"), first[static_cast<std::size_t>(n - 30)])) << n;
    EXPECT_TRUE(SameBits(Real(b, "x"), first[static_cast<std::size_t>(n - 30)])) << n;
  }
}

// Every FMI 2.0 type through: in initialization mode outputs follow the
// inputs (UpdateOutputs sets and gets, as that mode allows); in step mode
// they are doStep's: an fmi2Get after an fmi2Set without fmi2DoStep is not
// allowed (FMI 2.0.4 section 4.2.4; the test FMUs refuse it), so
// UpdateOutputs calls nothing and the outputs declare no direct dependency
// (issue 37: both master algorithms set inputs then read outputs before
// doStep, 12 times in 4 steps). The tunable offset changes between steps;
// units as declared.
TEST(FmuUnit, Fmi2FeedthroughOfEveryType) {
  FmuUnit u("f", Fmu("feedthrough2"));
  auto& t = u.variables();
  EXPECT_EQ(Info(u, "in_a").unit, "rad/s");
  EXPECT_EQ(Info(u, "in_b").unit, "N.m");  // m2.kg.s-2 in linesim's spelling
  EXPECT_EQ(Info(u, "in_count").type, VarType::kInteger);
  EXPECT_EQ(Info(u, "in_flag").type, VarType::kBoolean);
  EXPECT_EQ(Info(u, "out_text").type, VarType::kString);
  EXPECT_EQ(Info(u, "offset").variability, cosim::Variability::kTunable);
  EXPECT_TRUE(Info(u, "out_a").depends_on.empty());
  EXPECT_NE(Info(u, "out_a").description.find("depends on in_a in initialization mode"),
            std::string::npos)
      << Info(u, "out_a").description;
  EXPECT_EQ(t.GetInteger(*t.Find("in_count")), 3);  // start values
  EXPECT_EQ(t.GetBoolean(*t.Find("in_flag")), true);
  EXPECT_EQ(t.GetString(*t.Find("in_text")), "start");

  u.Setup(0, kMs * 100);
  u.Initialize();
  EXPECT_EQ(Real(u, "out_a"), 0.5);
  EXPECT_EQ(t.GetString(*t.Find("out_text")), "start");
  SetReal(u, "in_a", 1.25);
  SetReal(u, "in_b", -2.5);
  t.SetInteger(*t.Find("in_count"), -123456);
  t.SetBoolean(*t.Find("in_flag"), false);
  t.SetString(*t.Find("in_text"), "hello FMU");
  u.UpdateOutputs();
  EXPECT_EQ(Real(u, "out_a"), 1.25);
  EXPECT_EQ(Real(u, "out_b"), -2.5);
  EXPECT_EQ(t.GetInteger(*t.Find("out_count")), -123456);
  EXPECT_EQ(t.GetBoolean(*t.Find("out_flag")), false);
  EXPECT_EQ(t.GetString(*t.Find("out_text")), "hello FMU");
  ASSERT_EQ(u.DoStep(0, kMs), StepResult::kOk);
  EXPECT_EQ(Real(u, "out_a"), 1.25);
  // Step mode: a new input is not read back before the next step (the FMU
  // would refuse the get), and the step gives it.
  SetReal(u, "in_a", 2.0);
  u.UpdateOutputs();
  EXPECT_EQ(Real(u, "out_a"), 1.25);
  SetReal(u, "offset", 0.5);  // tunable: given to the FMU before the next step
  ASSERT_EQ(u.DoStep(kMs, kMs), StepResult::kOk) << u.last_error();
  EXPECT_EQ(Real(u, "out_a"), 2.5);
  // An Integer beyond the FMI 2.0 (32-bit) range is named, not wrapped.
  t.SetInteger(*t.Find("in_count"), std::int64_t{1} << 40);
  EXPECT_EQ(u.DoStep(2 * kMs, kMs), StepResult::kError);
  EXPECT_NE(u.last_error().find("Int32 value 1099511627776 of 'in.count' is outside the Int32 "
                                "range [-2147483648, 2147483647]"),
            std::string::npos)
      << u.last_error();
}

// The same for FMI 3.0: Float64 (declaredType unit), Int32, Boolean, String.
TEST(FmuUnit, Fmi3FeedthroughOfEveryType) {
  FmuUnit u("f", Fmu("feedthrough3"));
  auto& t = u.variables();
  EXPECT_EQ(u.description().fmi_major, 3);
  EXPECT_EQ(Info(u, "speed_in").unit, "m/s");
  EXPECT_EQ(Info(u, "speed_out").unit, "m/s");
  EXPECT_EQ(t.GetInteger(*t.Find("count_in")), -7);
  EXPECT_EQ(t.GetString(*t.Find("text_in")), "start");
  u.Setup(0, 100 * kMs);
  u.Initialize();
  EXPECT_EQ(t.GetInteger(*t.Find("count_out")), -7);
  SetReal(u, "speed_in", -0.125);
  t.SetInteger(*t.Find("count_in"), 2147483647);
  t.SetBoolean(*t.Find("flag_in"), true);
  t.SetString(*t.Find("text_in"), "drei");
  ASSERT_EQ(u.DoStep(0, kMs), StepResult::kOk) << u.last_error();
  EXPECT_EQ(Real(u, "speed_out"), -0.125);
  EXPECT_EQ(t.GetInteger(*t.Find("count_out")), 2147483647);
  EXPECT_EQ(t.GetBoolean(*t.Find("flag_out")), true);
  EXPECT_EQ(t.GetString(*t.Find("text_out")), "drei");
  ASSERT_FALSE(u.messages().empty());
  EXPECT_NE(u.messages()[0].find("fmi3OK [logEvents] instantiated"), std::string::npos);
}

// A 2 x 3 Float64 array output and a fixed parameter array (FMI 3.0):
// y[i][j] = scale p[j] (i + 1) t, row-major, against that formula.
TEST(FmuUnit, Fmi3ArrayOutput) {
  FmuUnit u("a", Fmu("array3"));
  auto& t = u.variables();
  EXPECT_EQ(Info(u, "y").type, VarType::kRealArray);
  EXPECT_EQ(Info(u, "y").size, 6u);
  EXPECT_EQ(Info(u, "y").unit, "m");
  EXPECT_EQ(Info(u, "p").size, 3u);
  EXPECT_EQ(t.GetRealElement(*t.Find("p"), 2), 3.0);  // start "1 2 3"
  const std::vector<double> p = {2.0, -4.0, 0.5};
  t.SetRealArray(*t.Find("p"), p);
  u.Setup(0, 1000 * kMs);
  u.Initialize();
  SetReal(u, "scale", 0.75);
  const TimeNs h = 10 * kMs;
  for (int n = 0; n < 25; ++n) ASSERT_EQ(u.DoStep(n * h, h), StepResult::kOk) << u.last_error();
  const double time = cosim::NsToSeconds(24 * h) + cosim::NsToSeconds(h);  // as the FMU adds them
  const auto y = t.GetRealArray(*t.Find("y"));
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_DOUBLE_EQ(y[static_cast<std::size_t>(3 * i + j)],
                       0.75 * p[static_cast<std::size_t>(j)] * (i + 1) * time)
          << i << "," << j;
    }
  }
  // y depends directly on scale in initialization mode only (ModelStructure):
  // in step mode UpdateOutputs reads nothing back (FMI 3.0.2 Step Mode: no
  // fmi3Get after fmi3Set before fmi3DoStep), and the next step gives it.
  SetReal(u, "scale", 1.5);
  u.UpdateOutputs();
  EXPECT_DOUBLE_EQ(t.GetRealElement(*t.Find("y"), 0), 0.75 * 2.0 * time);
  ASSERT_EQ(u.DoStep(25 * h, h), StepResult::kOk) << u.last_error();
  const double later = time + cosim::NsToSeconds(h);
  EXPECT_DOUBLE_EQ(t.GetRealElement(*t.Find("y"), 0), 1.5 * 2.0 * later);
}

// fixedInternalStepSize = 1 ms is information: a 1.5 ms communication step
// goes to the FMU, which refuses it (array3 returns fmi3Error, logging why),
// and the unit reports the FMU's status and log. After that error the
// standard allows no fmi3Terminate (FMI 3.0 section 2.2.3): Terminate()
// calls none (the test FMU logs every fmi3Terminate), and no further step.
TEST(FmuUnit, AStepTheFmuRefusesIsTheFmusToRefuse) {
  FmuUnit u("a", Fmu("array3"));
  u.Setup(0, 100 * kMs);
  u.Initialize();
  EXPECT_EQ(u.DoStep(0, 3 * kMs / 2), StepResult::kError);
  EXPECT_NE(u.last_error().find("fmi3DoStep returned fmi3Error"), std::string::npos)
      << u.last_error();
  EXPECT_NE(u.last_error().find("h is not a multiple of 1 ms"), std::string::npos)
      << u.last_error();
  u.Terminate();
  for (const auto& m : u.messages())
    EXPECT_EQ(m.find("fmi3Terminate called"), std::string::npos) << m;
  EXPECT_EQ(u.DoStep(0, kMs), StepResult::kError);
  EXPECT_NE(u.last_error().find("cannot be stepped again"), std::string::npos) << u.last_error();

  // A whole number of internal steps is taken, and Terminate is called.
  FmuUnit w("w", Fmu("array3"));
  w.Setup(0, 100 * kMs);
  w.Initialize();
  ASSERT_EQ(w.DoStep(0, 3 * kMs), StepResult::kOk) << w.last_error();
  w.Terminate();
  EXPECT_NE(w.messages().back().find("fmi3Terminate called"), std::string::npos)
      << w.messages().back();
}

TEST(FmuUnit, RefusesAVariableStepTheFmuCannotTake) {
  // canHandleVariableCommunicationStepSize = false: a changed step is refused.
  FmuUnit d("d", Fmu("discard2"));
  d.Setup(0, 100 * kMs);
  d.Initialize();
  ASSERT_EQ(d.DoStep(0, 10 * kMs), StepResult::kOk);
  EXPECT_EQ(d.DoStep(10 * kMs, 5 * kMs), StepResult::kError);
  EXPECT_NE(d.last_error().find("cannot handle a variable communication step size"),
            std::string::npos)
      << d.last_error();
}

// Without canSerializeFMUstate the FMU keeps the state: it restores into the
// unit that saved it (bit for bit), and into another unit with a named error.
TEST(FmuUnit, StateKeptByTheFmuRestoresIntoItsOwnUnitOnly) {
  FmuUnit a("a", Fmu("array3"));
  a.Setup(0, 1000 * kMs);
  a.Initialize();
  for (int n = 0; n < 5; ++n) ASSERT_EQ(a.DoStep(n * kMs, kMs), StepResult::kOk);
  const auto saved = a.SaveState();
  EXPECT_TRUE(saved.strings.empty());
  ASSERT_EQ(a.DoStep(5 * kMs, kMs), StepResult::kOk);
  const auto y1 = a.variables().GetRealArray(*a.variables().Find("y"));
  const std::vector<double> after(y1.begin(), y1.end());
  a.RestoreState(saved);
  ASSERT_EQ(a.DoStep(5 * kMs, kMs), StepResult::kOk);
  const auto y2 = a.variables().GetRealArray(*a.variables().Find("y"));
  EXPECT_EQ(std::memcmp(after.data(), y2.data(), after.size() * sizeof(double)), 0);

  FmuUnit b("a", Fmu("array3"));
  b.Setup(0, 1000 * kMs);
  b.Initialize();
  try {
    b.RestoreState(saved);
    FAIL() << "restored a kept state into another unit";
  } catch (const cosim::UnitError& e) {
    EXPECT_NE(std::string(e.what()).find("canSerializeFMUstate"), std::string::npos) << e.what();
  }
}

// fmi2Discard at a known time: t_discard = 0.35 s with 0.1 s steps, so the
// step from 0.3 s is discarded; the result names the call, the step and the
// FMU's own log line. Its state cannot be saved: named.
TEST(FmuUnit, DiscardBecomesTheStepResultDiscard) {
  FmuUnit u("d", Fmu("discard2"));
  SetReal(u, "t_discard", 0.35);
  u.Setup(0, 1000 * kMs);
  u.Initialize();
  const TimeNs h = 100 * kMs;
  for (int n = 0; n < 3; ++n) {
    ASSERT_EQ(u.DoStep(n * h, h), StepResult::kOk);
    EXPECT_EQ(Real(u, "x"), cosim::NsToSeconds(n * h) + cosim::NsToSeconds(h));
  }
  EXPECT_EQ(u.DoStep(3 * h, h), StepResult::kDiscard);
  const std::string& e = u.last_error();
  EXPECT_NE(e.find("fmi2DoStep returned fmi2Discard"), std::string::npos) << e;
  EXPECT_NE(e.find("from t = 0.3 s to 0.4 s"), std::string::npos) << e;
  EXPECT_NE(e.find("last successful time 0.35 s"), std::string::npos) << e;
  EXPECT_NE(e.find("cannot pass t_discard = 0.35"), std::string::npos) << e;
  try {
    (void)u.SaveState();
    FAIL() << "saved the state of an FMU that cannot";
  } catch (const cosim::UnitError& ex) {
    EXPECT_NE(std::string(ex.what()).find("canGetAndSetFMUstate"), std::string::npos);
  }
}

// An error status from doStep is named with the call, the step and the
// FMU's own log line (the Dahlquist FMU refuses h <= 0).
TEST(FmuUnit, AnErrorStatusIsNamedWithTheFmuLog) {
  FmuUnit u("d", Fmu("dahlquist"));
  u.Setup(0, 100 * kMs);
  u.Initialize();
  EXPECT_EQ(u.DoStep(0, 0), StepResult::kError);
  const std::string& e = u.last_error();
  EXPECT_NE(e.find("fmi2DoStep returned fmi2Error for the step of 0 s at t = 0 s"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("does the FMU refuse this step size?"), std::string::npos) << e;
  EXPECT_NE(e.find("step size 0 refused: must be > 0"), std::string::npos) << e;
}

// Guards issue 24's path escape: the binary's path is built from the
// modelIdentifier, and "../../../x/outside" (or an absolute one) made
// linesim dlopen a library from outside the unpacked FMU. The path is
// checked after resolving: one that leads out is refused, naming the
// attribute, and the library there is never loaded; one whose ".." stays
// inside the folder still loads.
TEST(FmuUnit, ModelIdentifierCannotLeadOutOfTheFmu) {
  namespace fs = std::filesystem;
  test::Scratch s("escape");
  // The library an attacker placed beside the unpacked FMU's folder (both
  // are in the temporary directory).
  const std::string outside = s / "outside.so";
  fs::copy_file(LINESIM_DAHLQUIST_SO, outside);
  std::string xml = test::ReadFile(LINESIM_SOURCE_DIR "/tests/units/fmu/fmus/dahlquist.xml");
  const std::string from = "modelIdentifier=\"dahlquist\"";
  const std::string so = test::ReadFile(LINESIM_DAHLQUIST_SO);
  const auto with_identifier = [&](const std::string& identifier) {
    std::string text = xml;
    text.replace(text.find(from), from.size(), "modelIdentifier=\"" + identifier + "\"");
    test::MakeZip(s / "escape.fmu",
                  {{"modelDescription.xml", text}, {"binaries/linux64/dahlquist.so", so}});
    return s / "escape.fmu";
  };
  const std::string identifier = "../../../" + s.path().filename().string() + "/outside";
  try {
    FmuUnit u("escape", with_identifier(identifier));
    ADD_FAILURE() << "loaded with modelIdentifier " << identifier;
  } catch (const FmuError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("modelIdentifier '" + identifier + "' makes the path 'binaries/linux64/" +
                        identifier +
                        ".so', which leads outside the unpacked FMU: refused "
                        "(every path built from the model description must stay in the FMU)"),
              std::string::npos)
        << what;
  }
  // An absolute identifier replaced the whole path (root / "/tmp/x.so" is
  // "/tmp/x.so"); now it is a name inside binaries/linux64/, which is not
  // there.
  const std::string absolute = (s.path() / "outside").string();
  try {
    FmuUnit u("escape", with_identifier(absolute));
    ADD_FAILURE() << "loaded with modelIdentifier " << absolute;
  } catch (const FmuError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("binaries/linux64/" + absolute + ".so is missing"), std::string::npos)
        << what;
  }
  EXPECT_EQ(::dlopen(outside.c_str(), RTLD_NOW | RTLD_NOLOAD), nullptr);
  // Resolved inside the folder: the FMU's own binary.
  FmuUnit inside("inside", with_identifier("sub/../dahlquist"));
  EXPECT_TRUE(inside.variables().Find("x"));
}

// Guards issue 24's quadratic loading in the naming step: FMI names that
// become one identifier ("a.,-+()", "a[]..." -> "a______") searched their
// suffix from _2 each time (20k of them: 2*10^8 set lookups). The suffix to
// try next is kept per identifier: the same names (_2, _3, ... in order),
// in linear time (no timing assertion: 20k names took 20.6 s before, 0.3 s
// now, measured; ctest's 300 s timeout stops a return to worse).
TEST(FmuUnit, NamesThatCollideAreMadeUniqueInLinearTime) {
  test::Scratch s("collide");
  constexpr std::size_t n = 20'000;
  const char kPunct[] = ".,-+()[]";
  std::string vars;
  for (std::size_t i = 0; i < n; ++i) {
    std::string name = "a";
    for (std::size_t k = i, d = 0; d < 6; ++d, k /= 8) name += kPunct[k % 8];
    vars += "<ScalarVariable name=\"" + name + "\" valueReference=\"" + std::to_string(i) +
            "\" causality=\"local\"><Real/></ScalarVariable>\n";
  }
  const std::string xml =
      "<?xml version=\"1.0\"?>\n<fmiModelDescription fmiVersion=\"2.0\" modelName=\"m\" "
      "guid=\"g\">\n<CoSimulation modelIdentifier=\"dahlquist\"/>\n<ModelVariables>\n" +
      vars + "</ModelVariables>\n</fmiModelDescription>\n";
  test::MakeZip(s / "c.fmu",
                {{"modelDescription.xml", xml},
                 {"binaries/linux64/dahlquist.so", test::ReadFile(LINESIM_DAHLQUIST_SO)}});
  FmuUnit u("c", s / "c.fmu");
  EXPECT_TRUE(u.variables().Find("a______"));
  EXPECT_TRUE(u.variables().Find("a_______2"));
  EXPECT_TRUE(u.variables().Find("a_______" + std::to_string(n)));
  EXPECT_FALSE(u.variables().Find("a_______" + std::to_string(n + 1)));
}

// The unit made without an FMU (`linesim inspect fmu`) says what is missing.
TEST(FmuUnit, WithoutAnFmuReportsPath) {
  FmuUnit u("f");
  EXPECT_EQ(u.variables().size(), 1u);
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].variable, "path");
  EXPECT_THROW(u.Initialize(), cosim::UnitError);
}

// LinesimUnit: SI spellings, base units, and units with a factor kept as
// they are (so that they connect only to the same unit).
TEST(FmuUnits, MapsToLinesimSpellings) {
  std::map<std::string, FmiUnit> defs;
  FmiUnit deg;
  deg.name = "deg";
  deg.has_base_unit = true;
  deg.exponents[7] = 1;
  deg.factor = 0.017453292519943295;
  defs["deg"] = deg;
  EXPECT_EQ(LinesimUnit("", defs), "1");
  EXPECT_EQ(LinesimUnit("m/s", defs), "m/s");
  EXPECT_EQ(LinesimUnit("m.s-1", defs), "m/s");
  EXPECT_EQ(LinesimUnit("m/s2", defs), "m/s2");
  EXPECT_EQ(LinesimUnit("kg.m2/s2", defs), "N.m");
  EXPECT_EQ(LinesimUnit("J", defs), "J");
  EXPECT_EQ(LinesimUnit("V.s/rad", defs), "V.s/rad");
  EXPECT_EQ(LinesimUnit("deg", defs), "deg");
  EXPECT_EQ(LinesimUnit("furlong", defs), "furlong");
}

// The staircase (fmus/staircase3.c): y = number of multiples of the period
// p = 0.25 s up to t, area = its integral, sum over j p < t of (t - j p).
// Stepped at 0.1 s, the events at 0.25 and 0.75 s fall inside steps (early
// returns the unit continues from lastSuccessfulTime: the FMU refuses a
// doStep that does not start there), the ones at 0.5 and 1.0 s at a step's
// end (an early return with lastSuccessfulTime = t + h: a step that
// succeeded). The values are the analytic ones up to rounding (1e-12:
// sums of ten terms below 1).
double StairArea(double t, double p) {
  double a = 0;
  for (int j = 1; j * p < t - 1e-9; ++j) a += t - j * p;
  return a;
}
TEST(FmuUnit, EarlyReturnIsContinuedFromTheTimeReached) {
  FmuUnit u("s", Fmu("staircase3"));
  EXPECT_TRUE(u.description().can_return_early);
  u.Setup(0, 1000 * kMs);
  u.Initialize();
  const TimeNs h = 100 * kMs;
  for (int k = 0; k < 10; ++k) {
    ASSERT_EQ(u.DoStep(k * h, h), StepResult::kOk) << k << ": " << u.last_error();
    const double t = 0.1 * (k + 1);
    EXPECT_EQ(Real(u, "y"), std::floor(t / 0.25 + 1e-9)) << t;
    EXPECT_NEAR(Real(u, "area"), StairArea(t, 0.25), 1e-12) << t;
    EXPECT_TRUE(u.stop_request().empty());
  }
  EXPECT_EQ(u.early_returns(), 2u);  // 0.25 s and 0.75 s
  EXPECT_EQ(Real(u, "events"), 4.0);
}

// FMI 3.0 terminateSimulation: the step's values (at the time reached) are
// read and the unit asks to end the run, naming the call; not an error.
TEST(FmuUnit, TerminateSimulationEndsTheRunWithTheValuesReached) {
  FmuUnit u("s", Fmu("staircase3"));
  SetReal(u, "t_stop", 0.75);
  u.Setup(0, 1000 * kMs);
  u.Initialize();
  const TimeNs h = 100 * kMs;
  for (int k = 0; k < 7; ++k) {
    ASSERT_EQ(u.DoStep(k * h, h), StepResult::kOk) << u.last_error();
    EXPECT_TRUE(u.stop_request().empty()) << k;
  }
  ASSERT_EQ(u.DoStep(7 * h, h), StepResult::kOk) << u.last_error();
  EXPECT_NE(u.stop_request().find("terminateSimulation = true"), std::string::npos)
      << u.stop_request();
  EXPECT_EQ(Real(u, "y"), 3.0);
  EXPECT_NEAR(Real(u, "area"), StairArea(0.75, 0.25), 1e-12);
  u.Terminate();
  EXPECT_NE(u.messages().back().find("fmi3Terminate called"), std::string::npos);
}

// FMI 2.0: fmi2Discard with fmi2Terminated = true (terminate2 ends at
// t_end = 0.355 s): the step's values at lastSuccessfulTime are read, the
// unit asks to end the run (no discard), and fmi2Terminate is then allowed.
TEST(FmuUnit, DiscardWithTerminatedEndsTheRun) {
  FmuUnit u("e", Fmu("terminate2"));
  u.Setup(0, 1000 * kMs);
  u.Initialize();
  const TimeNs h = 10 * kMs;
  for (int k = 0; k < 35; ++k) {
    ASSERT_EQ(u.DoStep(k * h, h), StepResult::kOk) << u.last_error();
    EXPECT_TRUE(u.stop_request().empty());
  }
  ASSERT_EQ(u.DoStep(35 * h, h), StepResult::kOk) << u.last_error();
  EXPECT_NE(u.stop_request().find("fmi2Discard with fmi2Terminated = true"), std::string::npos)
      << u.stop_request();
  EXPECT_NE(u.stop_request().find("last successful time 0.355 s"), std::string::npos)
      << u.stop_request();
  EXPECT_EQ(Real(u, "x"), 0.355);
  u.Terminate();
  EXPECT_NE(u.messages().back().find("fmi2Terminate called"), std::string::npos);
}

// Every FMI 3.0 scalar type (fmus/types3.c: each output is its input):
// floats as Reals (Float32 rounds to float: 0.1 comes back as
// double(float(0.1))), every integer type as an Integer given to the FMU
// only within its type's range, an enumeration only as one of its items,
// and a Float64 array sized by a UInt64 structural parameter (n = 3:
// y = (1, 2, 3) f32_in). The Binary input and output are left out: no
// variable of the unit, and the FMU keeps its own values. Guards issue 37:
// the Reference-FMUs' Feedthrough (FMI 3.0) was refused because its model
// structure lists a Binary output; types3 lists one too (491, depending on
// the Binary input 490).
TEST(FmuUnit, MapsEveryFmi3TypeWithItsRange) {
  FmuUnit u("t", Fmu("types3"));
  auto& table = u.variables();
  EXPECT_EQ(Info(u, "f32_in").type, VarType::kReal);
  EXPECT_EQ(Info(u, "i8_in").type, VarType::kInteger);
  EXPECT_EQ(Info(u, "u64_out").type, VarType::kInteger);
  EXPECT_EQ(Info(u, "mode_in").type, VarType::kInteger);
  EXPECT_NE(Info(u, "i8_in").description.find("Int8"), std::string::npos);
  EXPECT_NE(Info(u, "mode_in").description.find("enumeration 'Mode': 1 idle 2 run 5 stop"),
            std::string::npos)
      << Info(u, "mode_in").description;
  EXPECT_NE(Info(u, "f32_in").description.find("min -10, max 10, nominal 2"), std::string::npos)
      << Info(u, "f32_in").description;
  EXPECT_NE(Info(u, "f32_out").description.find("no start value"), std::string::npos);
  EXPECT_EQ(Info(u, "f32_in").description.find("no start value"), std::string::npos);
  EXPECT_FALSE(table.Find("blob"));
  EXPECT_FALSE(table.Find("blob_out"));
  ASSERT_EQ(u.description().left_out.size(), 2u);
  EXPECT_EQ(u.description().left_out[0], "blob (Binary)");
  EXPECT_EQ(u.description().left_out[1], "blob_out (Binary)");
  EXPECT_EQ(table.GetRealArray(*table.Find("y")).size(), 3u);

  u.Setup(0, 100 * kMs);
  u.Initialize();
  const auto set_int = [&](const char* name, std::int64_t v) {
    table.SetInteger(*table.Find(name), v);
  };
  const auto get_int = [&](const char* name) { return table.GetInteger(*table.Find(name)); };
  SetReal(u, "f32_in", 0.1);
  set_int("i8_in", -128);
  set_int("u8_in", 255);
  set_int("i16_in", -32768);
  set_int("u16_in", 65535);
  set_int("u32_in", 4294967295LL);
  set_int("i64_in", INT64_MIN);
  set_int("u64_in", INT64_MAX);
  set_int("mode_in", 5);
  ASSERT_EQ(u.DoStep(0, 10 * kMs), StepResult::kOk) << u.last_error();
  EXPECT_EQ(Real(u, "f32_out"), static_cast<double>(0.1f));
  EXPECT_EQ(get_int("i8_out"), -128);
  EXPECT_EQ(get_int("u8_out"), 255);
  EXPECT_EQ(get_int("i16_out"), -32768);
  EXPECT_EQ(get_int("u16_out"), 65535);
  EXPECT_EQ(get_int("u32_out"), 4294967295LL);
  EXPECT_EQ(get_int("i64_out"), INT64_MIN);
  EXPECT_EQ(get_int("u64_out"), INT64_MAX);
  EXPECT_EQ(get_int("mode_out"), 5);
  const auto y = table.GetRealArray(*table.Find("y"));
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(y[k], (k + 1) * static_cast<double>(0.1f)) << k;

  // Out of range: refused before the FMU sees it, naming variable, type and range.
  const struct {
    const char* name;
    std::int64_t value;
    const char* expected;
  } bad[] = {
      {"i8_in", 128, "Int8 value 128 of 'i8_in' is outside the Int8 range [-128, 127]"},
      {"u8_in", -1, "UInt8 value -1 of 'u8_in' is outside the UInt8 range [0, 255]"},
      {"u16_in", 65536, "UInt16 value 65536 of 'u16_in' is outside the UInt16 range [0, 65535]"},
      {"u32_in", -5, "UInt32 value -5 of 'u32_in' is outside the UInt32 range"},
      {"u64_in", -1, "UInt64 value -1 of 'u64_in' is outside the UInt64 range"},
      {"mode_in", 3,
       "value 3 of 'mode_in' is no item of enumeration 'Mode': 1 (idle), 2 (run), 5 (stop)"},
  };
  for (const auto& b : bad) {
    FmuUnit w("w", Fmu("types3"));
    w.Setup(0, 100 * kMs);
    w.Initialize();
    w.variables().SetInteger(*w.variables().Find(b.name), b.value);
    EXPECT_EQ(w.DoStep(0, 10 * kMs), StepResult::kError) << b.name;
    EXPECT_NE(w.last_error().find(b.expected), std::string::npos) << w.last_error();
  }
  FmuUnit w("w", Fmu("types3"));
  w.Setup(0, 100 * kMs);
  w.Initialize();
  SetReal(w, "f32_in", 1e39);  // FLT_MAX is 3.4e38
  EXPECT_EQ(w.DoStep(0, 10 * kMs), StepResult::kError);
  EXPECT_NE(w.last_error().find("is outside the Float32 range"), std::string::npos)
      << w.last_error();
}

}  // namespace
}  // namespace linesim::fmu
