// Step rejection (master.retry): a discarded step is undone for every unit
// that took part and retried smaller, on divisors of the master step, then
// the step grows back; identical results when nothing discards; a step
// below the minimum fails the run naming unit, time and cause. And the two
// algorithms behind one interface.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cosim/master.h"
#include "cosim/observers.h"
#include "tests/cosim/test_units.h"

namespace linesim::cosim {
namespace {

using test_units::CouplingUnit;
using test_units::Mass1Unit;
using test_units::StepCall;
using test_units::TwoMassParams;
using ::testing::HasSubstr;

constexpr TimeNs kUs = 1'000;
constexpr TimeNs kMs = 1'000'000;

/// Output y = the end time of its last step (s). It discards a step that
/// would cross `edge` (edge strictly inside (t, t + dt)); a step that ends
/// on the edge is accepted: an event the unit wants to meet exactly, as a
/// variable-step FMU does by returning fmi2Discard. Records every call,
/// discarded ones too (the record is not part of its state).
class EdgeUnit : public Unit {
 public:
  EdgeUnit(std::string name, TimeNs edge) : Unit("Edge", std::move(name)), edge_(edge) {
    variables().Output("y", "s", &y_, "end of the last step", {});
  }
  StepResult DoStep(TimeNs t, TimeNs dt) override {
    ClearError();
    calls.push_back({t, dt});
    if (t < edge_ && edge_ < t + dt) {
      Fail("would cross the edge at " + FormatSeconds(edge_) + " s");
      return StepResult::kDiscard;
    }
    y_ = NsToSeconds(t + dt);
    return StepResult::kOk;
  }
  std::vector<StepCall> calls;

 private:
  TimeNs edge_;
  double y_ = 0.0;
};

/// The integral of its input over time, kept exactly in integer
/// nanoseconds for a unit input u = 1 (x = t), so that one step counted
/// twice (a discarded step not undone) shows to the last bit.
class TimeIntegral : public Unit {
 public:
  explicit TimeIntegral(std::string name) : Unit("TimeIntegral", std::move(name)) {
    variables().Input("u", "1", &u_, "integrand (only 1 is integrated exactly)");
    variables().Output("x", "s", &x_, "integral of u dt", {});
  }
  StepResult DoStep(TimeNs, TimeNs dt) override {
    ns_ += static_cast<TimeNs>(u_) * dt;
    x_ = NsToSeconds(ns_);
    return StepResult::kOk;
  }
  TimeNs integral_ns() const { return ns_; }

 protected:
  void SaveInternal(UnitState& s) const override { s.integers.push_back(ns_); }
  void RestoreInternal(const UnitState& s) override { ns_ = s.integers.at(0); }

 private:
  double u_ = 1.0;
  double x_ = 0.0;
  TimeNs ns_ = 0;
};

MasterOptions RetryOptions(Algorithm a, TimeNs stop, TimeNs min_step = 1 * kUs) {
  MasterOptions o;
  o.algorithm = a;
  o.base_step = kMs;
  o.stop = stop;
  o.retry.enabled = true;
  o.retry.min_step = min_step;
  return o;
}

// Guards the retry itself: which steps are tried, from where, and that the
// run goes on past the discard at the master's step. Edge at 2.25 ms, master
// step 1 ms, shrink 0.5, grow 2. By hand: [2, 3] crosses it (discarded),
// [2, 2.5] too, [2, 2.25] ends on it (accepted); the step grows to 0.5 ms:
// [2.25, 2.75]; grows to 1 ms but only 0.25 ms remain to the master's point
// 3 ms: [2.75, 3]; then 1 ms steps again. Two rejections, smallest 0.25 ms.
// The integrating unit beside it is undone with every discard: its
// integral of 1 is exactly the time (int64 ns).
TEST(MasterRetry, ShrinksToMeetTheEdgeThenGrowsBack) {
  for (Algorithm alg : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    System system;
    auto& edge = static_cast<EdgeUnit&>(
        system.Add(std::make_unique<EdgeUnit>("edge", 2 * kMs + 250 * kUs)));
    auto& integral =
        static_cast<TimeIntegral&>(system.Add(std::make_unique<TimeIntegral>("integral")));
    Master master(system, RetryOptions(alg, 5 * kMs));
    const RunResult r = master.Run();
    ASSERT_TRUE(r.ok) << r.ErrorText();
    EXPECT_EQ(r.end_time, 5 * kMs);
    EXPECT_EQ(r.base_steps, 5);
    EXPECT_EQ(r.rejected_steps, 2);
    EXPECT_EQ(r.smallest_step, 250 * kUs);
    const std::vector<std::pair<TimeNs, TimeNs>> expected = {
        {0, kMs},
        {kMs, kMs},
        {2 * kMs, kMs},                     // discarded
        {2 * kMs, 500 * kUs},               // discarded
        {2 * kMs, 250 * kUs},               // on the edge
        {2 * kMs + 250 * kUs, 500 * kUs},   // grown
        {2 * kMs + 750 * kUs, 250 * kUs},   // to the master's point
        {3 * kMs, kMs},
        {4 * kMs, kMs}};
    ASSERT_EQ(edge.calls.size(), expected.size()) << ToString(alg);
    for (std::size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ(edge.calls[i].t, expected[i].first) << ToString(alg) << " call " << i;
      EXPECT_EQ(edge.calls[i].dt, expected[i].second) << ToString(alg) << " call " << i;
    }
    EXPECT_EQ(integral.integral_ns(), 5 * kMs) << ToString(alg);
    EXPECT_EQ(master.current_step(), kMs);
  }
}

// Guards the values exchanged across a retried step: a restored unit's
// inputs come back with it, and the sub-steps exchange values at their
// own points. The sink integrates the edge unit's output y (the end time of
// its last step); over [2, 3] ms with Gauss-Seidel each sub-step sees the y
// its predecessor just computed, so the integral is the sum of dt * (t +
// dt): 1*1 + 1*2 + 0.25*2.25 + 0.5*2.75 + 0.25*3 (ms^2) = 5.6875 ms^2 at 3 ms.
TEST(MasterRetry, SubStepsExchangeValuesAtTheirOwnPoints) {
  // y * dt summed exactly: y in s, dt in ns; every value here is exact in
  // binary (multiples of 1/4 ms in s are not, so compare to 1e-18).
  class Product : public Unit {
   public:
    Product() : Unit("Product", "sink") { variables().Input("y", "s", &y_, "time"); }
    StepResult DoStep(TimeNs, TimeNs dt) override {
      sum_ += y_ * NsToSeconds(dt);
      return StepResult::kOk;
    }
    double sum() const { return sum_; }

   protected:
    void SaveInternal(UnitState& s) const override { s.reals.push_back(sum_); }
    void RestoreInternal(const UnitState& s) override { sum_ = s.reals.at(0); }

   private:
    double y_ = 0.0;
    double sum_ = 0.0;
  };
  System system;
  system.Add(std::make_unique<EdgeUnit>("edge", 2 * kMs + 250 * kUs));
  auto& sink = static_cast<Product&>(system.Add(std::make_unique<Product>()));
  system.Connect("edge.y", "sink.y");
  Master master(system, RetryOptions(Algorithm::kGaussSeidel, 3 * kMs));
  const RunResult r = master.Run();
  ASSERT_TRUE(r.ok) << r.ErrorText();
  EXPECT_NEAR(sink.sum(), 5.6875e-6, 1e-18);
}

// Guards determinism and the "off changes nothing, on changes nothing when
// nothing discards" promise: the two-mass benchmark recorded every step is
// the same bytes with retry off and on, for both algorithms.
TEST(MasterRetry, IdenticalResultsWhenNothingDiscards) {
  const auto record = [](Algorithm alg, bool retry) {
    System system;
    TwoMassParams p;
    system.Add(std::make_unique<Mass1Unit>(p));
    system.Add(std::make_unique<CouplingUnit>(p));
    system.Connect("mass1.x", "coupling.x1");
    system.Connect("mass1.v", "coupling.v1");
    system.Connect("coupling.force", "mass1.force");
    MasterOptions o;
    o.algorithm = alg;
    o.base_step = kMs;
    o.stop = 500 * kMs;
    o.retry.enabled = retry;
    Master master(system, o);
    std::ostringstream csv;
    CsvRecorder recorder(csv, ResolveProbes(system, {"mass1.*", "coupling.*"}));
    master.AddObserver(&recorder);
    const RunResult r = master.Run();
    EXPECT_TRUE(r.ok) << r.ErrorText();
    EXPECT_EQ(r.rejected_steps, 0);
    return csv.str();
  };
  for (Algorithm alg : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    const std::string off = record(alg, false);
    EXPECT_GT(off.size(), 500u * 10u);
    EXPECT_EQ(off, record(alg, true)) << ToString(alg);
  }
}

// Guards the floor: a discard that would need a step below min_step_s
// fails the run with the unit, the time of the discarded step, the phase
// and the cause. Edge at 2.3 ms, minimum 0.1 ms: [2, 2.25] is accepted
// after two rejections, then from 2.25 ms the steps 0.5 (grown), 0.25 and
// 0.125 ms all cross 2.3 ms; the next, 62.5 us, is below the minimum.
TEST(MasterRetry, StepBelowTheMinimumFailsNamingUnitTimeAndCause) {
  System system;
  system.Add(std::make_unique<EdgeUnit>("edge", 2 * kMs + 300 * kUs));
  Master master(system, RetryOptions(Algorithm::kGaussSeidel, 5 * kMs, 100 * kUs));
  const RunResult r = master.Run();
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.end_time, 2 * kMs);  // the last master point all units reached
  ASSERT_EQ(r.errors.size(), 1u);
  const RunError& e = r.errors[0];
  EXPECT_EQ(e.unit, "edge");
  EXPECT_EQ(e.unit_type, "Edge");
  ASSERT_TRUE(e.time.has_value());
  EXPECT_EQ(*e.time, 2 * kMs + 250 * kUs);
  EXPECT_EQ(e.phase, RunPhase::kStep);
  EXPECT_EQ(e.cause,
            "discarded the step of 0.000125 s (would cross the edge at 0.0023 s); a step of "
            "0.0000625 s would be below master.retry.min_step_s = 0.0001 s");
  EXPECT_EQ(e.message, "unit 'edge' (Edge) at t = 0.00225 s: " + e.cause);
  EXPECT_EQ(r.rejected_steps, 2 + 3);
}

// Guards the multirate rule: a unit slower than the master keeps its own
// step (the master's retry does not change it), so its discard fails the
// run and says why; a slower unit that does not discard is undone with the
// others (its integral stays exact).
TEST(MasterRetry, SlowerUnitsKeepTheirStep) {
  {
    System system;
    system.Add(std::make_unique<EdgeUnit>("fast", 2 * kMs + 250 * kUs));
    auto& slow = static_cast<TimeIntegral&>(
        system.Add(std::make_unique<TimeIntegral>("slow"), 2 * kMs));
    Master master(system, RetryOptions(Algorithm::kJacobi, 6 * kMs));
    const RunResult r = master.Run();
    ASSERT_TRUE(r.ok) << r.ErrorText();
    EXPECT_EQ(slow.integral_ns(), 6 * kMs);
  }
  {
    System system;
    system.Add(std::make_unique<EdgeUnit>("slow", 2 * kMs + 250 * kUs), 2 * kMs);
    Master master(system, RetryOptions(Algorithm::kJacobi, 6 * kMs));
    const RunResult r = master.Run();
    ASSERT_FALSE(r.ok);
    ASSERT_EQ(r.errors.size(), 1u);
    EXPECT_EQ(r.errors[0].unit, "slow");
    EXPECT_EQ(r.errors[0].time, 2 * kMs);
    EXPECT_THAT(r.errors[0].cause, HasSubstr("is a multiple of the master step, which "
                                             "master.retry does not shrink"));
  }
}

// Guards the option's checks: shrink in (0, 1), grow >= 1, a minimum step
// within (0, master step].
TEST(MasterRetry, RefusesBadRetryOptions) {
  System system;
  system.Add(std::make_unique<EdgeUnit>("edge", kMs));
  MasterOptions o = RetryOptions(Algorithm::kGaussSeidel, 4 * kMs, 2 * kMs);
  o.retry.shrink = 1.0;
  o.retry.grow = 0.5;
  try {
    Master master(system, o);
    FAIL() << "accepted bad retry options";
  } catch (const ConfigError& e) {
    const std::string all = e.what();
    EXPECT_THAT(all, HasSubstr("master.retry.shrink must be in (0, 1)"));
    EXPECT_THAT(all, HasSubstr("master.retry.grow must be at least 1"));
    EXPECT_THAT(all, HasSubstr("master.retry.min_step_s 0.002 s must be positive and at most"));
  }
}

// Guards the structured errors of the master's other phases: a unit that
// throws in Initialize with the variable it concerns, and a NaN output
// after a step, each with unit, time, phase, variable and cause.
TEST(RunErrors, CarryUnitTimePhaseVariableAndCause) {
  {
    class BadParameter : public Unit {
     public:
      BadParameter() : Unit("Bad", "b") {}
      void Initialize() override { throw UnitError(Where() + ": gain must be > 0", "gain"); }
      StepResult DoStep(TimeNs, TimeNs) override { return StepResult::kOk; }
    };
    System system;
    system.Add(std::make_unique<BadParameter>());
    MasterOptions o;
    o.stop = 3 * kMs;
    Master master(system, o);
    const RunResult r = master.Run();
    ASSERT_EQ(r.errors.size(), 1u);
    const RunError& e = r.errors[0];
    EXPECT_EQ(e.unit, "b");
    EXPECT_EQ(e.time, TimeNs{0});
    EXPECT_EQ(e.phase, RunPhase::kInitialize);
    EXPECT_EQ(e.variable, "gain");
    EXPECT_EQ(e.cause, "gain must be > 0");
    EXPECT_EQ(e.message, "unit 'b' (Bad) at t = 0 s: initialize failed: gain must be > 0");
  }
  {
    System system;
    system.Add(std::make_unique<test_units::FaultyUnit>(
        "bad", test_units::FaultyUnit::Mode::kNaN, 3 * kMs));
    MasterOptions o;
    o.stop = 10 * kMs;
    Master master(system, o);
    const RunResult r = master.Run();
    ASSERT_EQ(r.errors.size(), 1u);
    const RunError& e = r.errors[0];
    EXPECT_EQ(e.unit, "bad");
    EXPECT_EQ(e.time, 3 * kMs);  // the time of the output: the step's end
    EXPECT_EQ(e.phase, RunPhase::kStep);
    EXPECT_EQ(e.variable, "y");
    EXPECT_EQ(e.cause, "output 'y' is nan");
    EXPECT_EQ(ToString(e.phase), "step");
  }
}

// Guards the separation of algorithm and execution: the scenario's name
// picks the class.
TEST(StepAlgorithms, ChosenByName) {
  for (Algorithm a : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    EXPECT_EQ(MakeAlgorithm(a)->kind(), a);
    System system;
    system.Add(std::make_unique<EdgeUnit>("edge", kMs));
    MasterOptions o;
    o.algorithm = a;
    o.stop = 2 * kMs;
    Master master(system, o);
    EXPECT_EQ(master.algorithm().kind(), a);
  }
}

}  // namespace
}  // namespace linesim::cosim
