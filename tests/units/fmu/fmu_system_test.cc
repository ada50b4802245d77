// FMU units with native units in one cosim::System: connections checked
// across the boundary (unit of measure, type), and a run of the master.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

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
  system.Add(std::make_unique<StepSignalUnit>("rate", 1, "m/s",
                                              std::vector<StepSignalUnit::Step>{{0, {0.3}}}));
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
  system.Add(
      std::make_unique<StepSignalUnit>("volts", 1, "V", std::vector<StepSignalUnit::Step>{}));
  system.Add(std::make_unique<FmuUnit>("plant", Fmu("dahlquist")));
  system.Add(std::make_unique<FmuUnit>("through", Fmu("feedthrough2")));
  system.Connect("volts.value[0]", "plant.u");     // V into m/s
  system.Connect("plant.x", "through.in_a");       // m into rad/s
  system.Connect("through.out_count", "plant.u");  // Integer into Real (and a second source)
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

// Two feedthrough FMUs in a chain, under both algorithms: each output is
// what doStep computed from the input held over the step (no fmi3Get after
// fmi3Set before fmi3DoStep: FMI 3.0.2 Step Mode, which the test FMUs
// enforce by refusing), so the speed's change at 50 ms reaches f3b's
// output a step per FMU later; the run finishes without an FMU error.
TEST(FmuSystem, FeedthroughChainAcrossFmiVersions) {
  for (const auto algorithm : {cosim::Algorithm::kJacobi, cosim::Algorithm::kGaussSeidel}) {
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
    options.algorithm = algorithm;
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
}

// A variable linesim leaves out (types3's Binary output) refuses the FMU
// only where a scenario connects it: then it is named as no variable of
// the unit (issue 37: the whole FMU was refused at loading).
TEST(FmuSystem, ALeftOutVariableIsRefusedOnlyWhereConnected) {
  {
    cosim::System system;
    system.Add(std::make_unique<FmuUnit>("t", Fmu("types3")));
    EXPECT_NO_THROW(system.Build());
  }
  cosim::System system;
  system.Add(std::make_unique<FmuUnit>("t", Fmu("types3")));
  system.Add(std::make_unique<FmuUnit>("u", Fmu("types3")));
  system.Connect("t.blob_out", "u.i8_in");
  try {
    system.Build();
    FAIL() << "connected a left-out Binary output";
  } catch (const cosim::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("blob_out"), std::string::npos) << e.what();
  }
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

// The step-rejecting master on an FMU that discards: edge2 refuses a step
// over t_edge = 0.375 s (fmi2Discard). Master step 0.25 s, retry on
// (shrink 0.5, grow 2), every time exact in binary. By hand: [0, 0.25];
// [0.25, 0.5] passes the edge: discarded, the FMU set back (setFMUstate);
// [0.25, 0.375] ends on it; the step grows to 0.25 s but only 0.125 s
// remain to 0.5 s: [0.375, 0.5]; then [0.5, 0.75], [0.75, 1]. The run
// continues past the discard and ends with x = 1 s; one step rejected, the
// smallest 0.125 s. Without retry the same run stops at 0.25 s.
TEST(FmuSystem, RetryStepsPastADiscardWithASmallerStep) {
  for (const bool retry : {false, true}) {
    cosim::System system;
    auto& edge = system.Add(std::make_unique<FmuUnit>("edge", Fmu("edge2")));
    cosim::MasterOptions options;
    options.base_step = 250 * kMs;
    options.stop = 1000 * kMs;
    options.retry.enabled = retry;
    cosim::Master master(system, options);
    std::vector<double> x_at_points;
    const auto result = [&] {
      master.Start();
      x_at_points.push_back(edge.variables().GetReal(*edge.variables().Find("x")));
      // Step() is false at the stop time, or after a failure (no point then).
      for (bool more = true; more;) {
        const TimeNs before = master.time();
        more = master.Step();
        if (master.time() > before) {
          x_at_points.push_back(edge.variables().GetReal(*edge.variables().Find("x")));
        }
      }
      return master.Finish();
    }();
    if (!retry) {
      ASSERT_FALSE(result.ok);
      EXPECT_EQ(result.end_time, 250 * kMs);
      EXPECT_EQ(result.errors[0].unit, "edge");
      EXPECT_EQ(result.errors[0].time, 250 * kMs);
      EXPECT_NE(result.errors[0].cause.find("would pass t_edge = 0.375 s"), std::string::npos)
          << result.errors[0].message;
      continue;
    }
    ASSERT_TRUE(result.ok) << result.ErrorText();
    EXPECT_EQ(result.end_time, 1000 * kMs);
    EXPECT_EQ(result.rejected_steps, 1);
    EXPECT_EQ(result.smallest_step, 125 * kMs);
    // x = the time, at the master's points: the sub-steps are inside.
    EXPECT_EQ(x_at_points, (std::vector<double>{0.0, 0.25, 0.5, 0.75, 1.0}));
  }
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

// An FMU that asks to end the simulation ends the run normally after that
// step: ok, end_time the end of that master step, the FMU's last values
// kept, the reason in RunResult::ended_by; with and without master.retry.
// terminate2 ends at t_end = 0.355 s, inside the step [0.35, 0.36] s.
TEST(FmuSystem, AnFmuThatAsksToTerminateEndsTheRunNormally) {
  for (bool retry : {false, true}) {
    cosim::System system;
    system.Add(std::make_unique<StepSignalUnit>("rate", 1, "m/s",
                                                std::vector<StepSignalUnit::Step>{{0, {0.3}}}));
    auto& end = system.Add(std::make_unique<FmuUnit>("end", Fmu("terminate2")));
    auto& plant = system.Add(std::make_unique<FmuUnit>("plant", Fmu("dahlquist")));
    system.Connect("rate.value[0]", "plant.u");
    cosim::MasterOptions options;
    options.base_step = 10 * kMs;
    options.stop = 1000 * kMs;
    options.retry.enabled = retry;
    cosim::Master master(system, options);
    const auto result = master.Run();
    ASSERT_TRUE(result.ok) << result.ErrorText();
    EXPECT_TRUE(result.errors.empty()) << result.ErrorText();
    EXPECT_EQ(result.end_time, 360 * kMs);
    EXPECT_EQ(result.base_steps, 36);
    EXPECT_NE(result.ended_by.find("unit 'end' (fmu): fmi2DoStep returned fmi2Discard with "
                                   "fmi2Terminated = true"),
              std::string::npos)
        << result.ended_by;
    EXPECT_EQ(end.variables().GetReal(*end.variables().Find("x")), 0.355);
    // The other FMU stepped to the same time (x' = -x + 0.3, x(0) = 1).
    EXPECT_NEAR(plant.variables().GetReal(*plant.variables().Find("x")),
                0.3 + 0.7 * std::exp(-0.36), 1e-14);
  }
}

// A run with the staircase's early returns reaches the stop time with the
// analytic values (y = 4 steps of 0.25 s in 1 s, area = 0.25 (1 + 2 + 3)).
TEST(FmuSystem, EarlyReturnsRunToTheEnd) {
  cosim::System system;
  auto& stairs = system.Add(std::make_unique<FmuUnit>("stairs", Fmu("staircase3")));
  cosim::MasterOptions options;
  options.base_step = 100 * kMs;
  options.stop = 1000 * kMs;
  cosim::Master master(system, options);
  const auto result = master.Run();
  ASSERT_TRUE(result.ok) << result.ErrorText();
  EXPECT_TRUE(result.ended_by.empty());
  EXPECT_EQ(result.end_time, 1000 * kMs);
  EXPECT_EQ(stairs.variables().GetReal(*stairs.variables().Find("y")), 4.0);
  EXPECT_NEAR(stairs.variables().GetReal(*stairs.variables().Find("area")), 1.5, 1e-12);
}

}  // namespace
}  // namespace linesim::fmu
