// FMU units with native units in one cosim::System: connections checked
// across the boundary (unit of measure, type), and a run of the master.
#include <gtest/gtest.h>

#include <cmath>

#include "cosim/master.h"
#include "cosim/system.h"
#include "tests/units/fmu/fmu_test_support.h"
#include "units/fmu/fmu_unit.h"
#include "units/sources/step_signal.h"

namespace linesim::fmu {
namespace {

using cosim::TimeNs;
using sources::StepSignalUnit;
using test::Fmu;

constexpr TimeNs kMs = 1'000'000;

// A step_signal in m/s drives the Dahlquist FMU's input u (m/s): the run
// follows the closed form of x' = -k x + u for u = 0.3 from t = 0,
// x(t) = u/k + (x0 - u/k) e^{-k t}, with k = x0 = 1 (the FMU's start values).
TEST(FmuSystem, NativeSourceDrivesAnFmu) {
  cosim::System system;
  system.Add(std::make_unique<StepSignalUnit>(
      "rate", 1, "m/s", std::vector<StepSignalUnit::Step>{{0, {0.3}}}));
  auto& fmu = system.Add(std::make_unique<FmuUnit>("plant", Fmu("dahlquist")));
  system.Connect("rate.value[0]", "plant.u");
  cosim::MasterOptions options;
  options.base_step = 10 * kMs;
  options.stop = 1000 * kMs;
  cosim::Master master(system, options);
  const auto result = master.Run();
  ASSERT_TRUE(result.ok) << result.ErrorText();
  const double exact = 0.3 + (1.0 - 0.3) * std::exp(-1.0);
  EXPECT_NEAR(fmu.variables().GetReal(*fmu.variables().Find("x")), exact, 1e-14);
}

// An FMU output feeds a native unit's input of another unit: refused, named.
TEST(FmuSystem, MismatchedUnitsAcrossTheBoundaryAreRefused) {
  cosim::System system;
  system.Add(std::make_unique<StepSignalUnit>("volts", 1, "V",
                                              std::vector<StepSignalUnit::Step>{}));
  system.Add(std::make_unique<FmuUnit>("plant", Fmu("dahlquist")));
  system.Add(std::make_unique<FmuUnit>("through", Fmu("feedthrough2")));
  system.Connect("volts.value[0]", "plant.u");     // V into m/s
  system.Connect("plant.x", "through.in_a");        // m into rad/s
  system.Connect("through.out_count", "plant.u");   // Integer into Real (and a second source)
  try {
    system.Build();
    FAIL() << "built a system with mismatched units";
  } catch (const cosim::ConfigError& e) {
    const std::string all = e.what();
    EXPECT_NE(all.find("units of measure differ: volts.value[0] is in 'V', plant.u is in 'm/s'"),
              std::string::npos)
        << all;
    EXPECT_NE(all.find("units of measure differ: plant.x is in 'm', through.in_a is in 'rad/s'"),
              std::string::npos)
        << all;
    EXPECT_NE(all.find("type mismatch"), std::string::npos) << all;
  }
}

// Direct feedthrough through two FMUs in a chain (ModelStructure's
// dependencies give the step order); and the FMI 3.0 feedthrough next to the
// FMI 2.0 one.
TEST(FmuSystem, FeedthroughChainAcrossFmiVersions) {
  cosim::System system;
  system.Add(std::make_unique<StepSignalUnit>(
      "speed", 1, "m/s", std::vector<StepSignalUnit::Step>{{0, {2.5}}, {50 * kMs, {-1.0}}}));
  system.Add(std::make_unique<FmuUnit>("f3", Fmu("feedthrough3")));
  auto& f3b = system.Add(std::make_unique<FmuUnit>("f3b", Fmu("feedthrough3")));
  system.Connect("speed.value[0]", "f3.speed_in");
  system.Connect("f3.speed_out", "f3b.speed_in");
  system.Connect("f3.count_out", "f3b.count_in");
  system.Connect("f3.text_out", "f3b.text_in");
  cosim::MasterOptions options;
  options.base_step = 10 * kMs;
  options.stop = 100 * kMs;
  cosim::Master master(system, options);
  const auto result = master.Run();
  ASSERT_TRUE(result.ok) << result.ErrorText();
  const auto& t = f3b.variables();
  EXPECT_EQ(t.GetReal(*t.Find("speed_out")), -1.0);
  EXPECT_EQ(t.GetInteger(*t.Find("count_out")), -7);
  EXPECT_EQ(t.GetString(*t.Find("text_out")), "start");
}

// fmi2Discard in a fixed-step master: the run stops at the discarded step,
// naming unit and time (master.retry is off by default). t_discard is
// 0.5 s; the FMU discards a step ending after it: 0.4 + 0.1 is exactly 0.5
// in binary floating point, so the step from 0.5 s is the first.
TEST(FmuSystem, DiscardStopsAFixedStepRunNamingUnitAndTime) {
  cosim::System system;
  system.Add(std::make_unique<FmuUnit>("d", Fmu("discard2")));
  cosim::MasterOptions options;
  options.base_step = 100 * kMs;
  options.stop = 1000 * kMs;
  cosim::Master master(system, options);
  const auto result = master.Run();
  ASSERT_FALSE(result.ok);
  ASSERT_EQ(result.errors.size(), 1u);
  const std::string& e = result.errors[0].message;
  EXPECT_NE(e.find("unit 'd' (fmu) at t = 0.5 s"), std::string::npos) << e;
  EXPECT_NE(e.find("discarded the step"), std::string::npos) << e;
  EXPECT_EQ(result.end_time, 500 * kMs);
  EXPECT_EQ(result.errors[0].unit, "d");
  EXPECT_EQ(result.errors[0].phase, cosim::RunPhase::kStep);
}

// master.retry needs the FMU's state before every step: discard2 does not
// offer canGetAndSetFMUstate, so a run with retry on is refused at its
// first step, in the retry phase, naming the missing capability (rather
// than failing later at the discard with nothing to go back to).
TEST(FmuSystem, RetryNeedsAnFmuThatCanSaveItsState) {
  cosim::System system;
  system.Add(std::make_unique<FmuUnit>("d", Fmu("discard2")));
  cosim::MasterOptions options;
  options.base_step = 100 * kMs;
  options.stop = 1000 * kMs;
  options.retry.enabled = true;
  cosim::Master master(system, options);
  const auto result = master.Run();
  ASSERT_FALSE(result.ok);
  ASSERT_EQ(result.errors.size(), 1u);
  const cosim::RunError& e = result.errors[0];
  EXPECT_EQ(e.unit, "d");
  EXPECT_EQ(e.time, TimeNs{0});
  EXPECT_EQ(e.phase, cosim::RunPhase::kRetry);
  EXPECT_NE(e.cause.find("canGetAndSetFMUstate"), std::string::npos) << e.message;
  EXPECT_EQ(result.end_time, 0);
}

}  // namespace
}  // namespace linesim::fmu
