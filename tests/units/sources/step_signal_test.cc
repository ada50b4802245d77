#include "units/sources/step_signal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace linesim::sources {
namespace {

constexpr cosim::TimeNs kMs = 1'000'000;

// Guards against an off-by-one at a switching time: the value at time t is
// the last step whose time is <= t (definition of a right-continuous step).
TEST(StepSignalUnit, ValueSwitchesExactlyAtStepTimes) {
  StepSignalUnit u("s", 2, "V", {{10 * kMs, {1, 2}}, {20 * kMs, {3, 4}}});
  auto& t = u.variables();
  t.SetValue(*t.Find("initial"), cosim::Value{std::vector<double>{-1, -2}});
  u.Setup(0, 100 * kMs);
  u.Initialize();
  const auto value = *t.Find("value");
  EXPECT_EQ(t.GetRealElement(value, 0), -1);
  u.DoStep(0, 9 * kMs);  // ends at 9 ms: before the first step
  EXPECT_EQ(t.GetRealElement(value, 1), -2);
  u.DoStep(9 * kMs, kMs);  // ends at 10 ms: on the first step
  EXPECT_EQ(t.GetRealElement(value, 0), 1);
  EXPECT_EQ(t.GetRealElement(value, 1), 2);
  u.DoStep(10 * kMs, 15 * kMs);  // ends at 25 ms: past the second step
  EXPECT_EQ(t.GetRealElement(value, 0), 3);
  EXPECT_EQ(t.GetRealElement(value, 1), 4);
}

// Guards against silently accepting a schedule that goes back in time.
TEST(StepSignalUnit, RefusesDecreasingStepTimes) {
  StepSignalUnit u("s", 1, "V", {{20 * kMs, {1}}, {10 * kMs, {2}}});
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].variable, "steps");
  EXPECT_EQ(problems[0].index, 1u);
  EXPECT_NE(problems[0].message.find("increase"), std::string::npos);
  // Also without the loader: Initialize refuses them.
  EXPECT_THROW(u.Initialize(), cosim::UnitError);
}

// Guards against a non-finite value reaching the output: it is refused at
// the parameter that holds it, not found later as a NaN output.
TEST(StepSignalUnit, RefusesNonFiniteValuesNamingTheStep) {
  StepSignalUnit u("s", 2, "V", {{10 * kMs, {1, 2}}, {20 * kMs, {3, std::nan("")}}});
  u.variables().SetRealArray(*u.variables().Find("initial"),
                             std::vector<double>{0, std::numeric_limits<double>::infinity()});
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].variable, "initial");
  EXPECT_EQ(problems[0].index, 1u);
  EXPECT_EQ(problems[0].message, "must be finite, got inf");
  EXPECT_EQ(problems[1].variable, "steps");
  EXPECT_EQ(problems[1].index, 1u);
  EXPECT_NE(problems[1].message.find("got nan"), std::string::npos) << problems[1].message;
  EXPECT_THROW(u.Initialize(), cosim::UnitError);
}

// Guards the constructor against a bad channel count (a negative count used
// to size vectors before it was checked) and against steps with the wrong
// number of values: both are errors that name the unit.
TEST(StepSignalUnit, RefusesBadCountsNamingTheUnit) {
  try {
    StepSignalUnit u("s", -1, "V", {});
    FAIL() << "count -1 accepted";
  } catch (const cosim::UnitError& e) {
    EXPECT_NE(std::string(e.what()).find("unit 's' (step_signal)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(StepSignalUnit("s", 2, "V", {{0, {1.0}}}), cosim::UnitError);
}

// Guards against the output unit of measure being lost (connections check it).
TEST(StepSignalUnit, OutputCarriesTheGivenUnitOfMeasure) {
  StepSignalUnit u("s", 3, "N.m", {});
  const auto& info = u.variables().info(*u.variables().Find("value"));
  EXPECT_EQ(info.unit, "N.m");
  EXPECT_EQ(info.size, 3u);
  EXPECT_EQ(info.causality, cosim::Causality::kOutput);
}

}  // namespace
}  // namespace linesim::sources
