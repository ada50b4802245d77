// The fixed-step master: multirate decimation, step checks, initial value
// propagation, the NaN/Inf guard and unit failures.

#include "cosim/master.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cosim/observers.h"
#include "tests/cosim/test_units.h"

namespace linesim::cosim {
namespace {

using test_units::FaultyUnit;
using test_units::PassThrough;
using test_units::RampSource;
using test_units::RecordingSink;
using test_units::StepCall;
using ::testing::HasSubstr;

constexpr TimeNs kMs = 1'000'000;

struct Multirate {
  System system;
  RampSource* source = nullptr;
  RecordingSink* sink = nullptr;
};

// Source every 2 ms, sink every 3 ms, base step 1 ms. The sink is declared
// first so that Gauss-Seidel must order by dependency, not declaration.
std::unique_ptr<Multirate> MakeMultirate() {
  auto m = std::make_unique<Multirate>();
  m->sink =
      static_cast<RecordingSink*>(&m->system.Add(std::make_unique<RecordingSink>("sink"), 3 * kMs));
  m->source =
      static_cast<RampSource*>(&m->system.Add(std::make_unique<RampSource>("source"), 2 * kMs));
  m->system.Connect("source.value", "sink.value");
  return m;
}

MasterOptions MultirateOptions(Algorithm a) {
  MasterOptions o;
  o.algorithm = a;
  o.base_step = kMs;
  o.stop = 24 * kMs;
  return o;
}

void ExpectCalls(const std::vector<StepCall>& calls, TimeNs step, TimeNs stop) {
  ASSERT_EQ(calls.size(), static_cast<std::size_t>(stop / step));
  for (std::size_t i = 0; i < calls.size(); ++i) {
    EXPECT_EQ(calls[i].t, static_cast<TimeNs>(i) * step) << "call " << i;
    EXPECT_EQ(calls[i].dt, step) << "call " << i;
  }
}

// Guards against: a unit stepping at the base rate instead of its own, a
// wrong dt, or float time drift in call times. Expected: the source at
// 0, 2, ..., 22 ms with dt = 2 ms, the sink at 0, 3, ..., 21 ms with 3 ms
// (24 ms run; steps are integer multiples of the 1 ms base step).
TEST(MasterMultirate, EachUnitStepsAtItsOwnMultipleOfTheBaseStep) {
  for (Algorithm a : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    auto m = MakeMultirate();
    Master master(m->system, MultirateOptions(a));
    EXPECT_EQ(master.decimation(0), 3);  // sink
    EXPECT_EQ(master.decimation(1), 2);  // source
    const RunResult r = master.Run();
    ASSERT_TRUE(r.ok);
    EXPECT_EQ(r.base_steps, 24);
    EXPECT_EQ(r.end_time, 24 * kMs);
    ExpectCalls(m->source->calls, 2 * kMs, 24 * kMs);
    ExpectCalls(m->sink->calls, 3 * kMs, 24 * kMs);
  }
}

// Guards variability through the master: parameters are set before Start;
// once the units are initialized a fixed parameter refuses a new value
// (the run keeps the value it was initialized with), and a saved state
// still restores into the locked unit.
TEST(MasterVariability, FixedParametersAreLockedOnceTheUnitsAreInitialized) {
  auto m = MakeMultirate();
  VariableTable& source = m->source->variables();
  source.SetReal(*source.Find("slope"), 2.0);  // before the run: fine
  Master master(m->system, MultirateOptions(Algorithm::kJacobi));
  EXPECT_FALSE(source.locked());
  master.Start();
  EXPECT_TRUE(source.locked());
  EXPECT_THROW(source.SetReal(*source.Find("slope"), 3.0), std::logic_error);
  EXPECT_EQ(source.GetReal(*source.Find("slope")), 2.0);
  const UnitState saved = m->source->SaveState();
  ASSERT_TRUE(master.Step());
  m->source->RestoreState(saved);
  EXPECT_EQ(source.GetReal(*source.Find("slope")), 2.0);
}

// Guards against: transferring when only the destination is due (which
// would leak the source's output between common points). Rule: a link
// transfers only when its destination is due and its source is at a
// communication point, i.e. at common multiples of 2 and 3 ms: 0, 6, 12,
// 18 ms. Jacobi transfers before anyone steps, so at t = 6k ms the sink gets
// the source's output for time 6k ms (the ramp value 0.006 k), and keeps it
// at t = 6k + 3 ms.
TEST(MasterMultirate, JacobiTransfersOnlyAtCommonCommunicationPoints) {
  auto m = MakeMultirate();
  Master master(m->system, MultirateOptions(Algorithm::kJacobi));
  ASSERT_TRUE(master.Run().ok);
  const std::vector<double> expected = {0.0, 0.0, 0.006, 0.006, 0.012, 0.012, 0.018, 0.018};
  EXPECT_EQ(m->sink->seen, expected);
}

// Guards against: Gauss-Seidel stepping the sink before its source, or
// transferring between common points. Rule: at t = 6k ms the source steps
// first (dependency order) to t + 2 ms, and the transfer at this common
// point then carries its new output, 0.006 k + 0.002; at 6k + 3 ms the
// source is not at a communication point, so the sink keeps that value.
TEST(MasterMultirate, GaussSeidelTransfersTheSourcesNewOutputAtCommonPoints) {
  auto m = MakeMultirate();
  Master master(m->system, MultirateOptions(Algorithm::kGaussSeidel));
  ASSERT_TRUE(master.Run().ok);
  EXPECT_EQ(m->system.dependency_order(), (std::vector<std::size_t>{1, 0}));
  const std::vector<double> expected = {0.002, 0.002, 0.008, 0.008, 0.014, 0.014, 0.020, 0.020};
  EXPECT_EQ(m->sink->seen, expected);
}

// Guards against: accepting a unit step the base step does not divide (the
// unit would step at drifting times). Message must name the unit.
TEST(MasterConfig, RefusesAUnitStepThatIsNotAMultipleOfTheBaseStep) {
  System system;
  system.Add(std::make_unique<RampSource>("fast"));
  system.Add(std::make_unique<RampSource>("odd"), 1'500'000);  // 1.5 ms
  MasterOptions o;
  o.base_step = kMs;
  o.stop = 30 * kMs;
  try {
    Master master(system, o);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.problems().size(), 1u) << e.what();
    EXPECT_THAT(e.problems()[0].message, HasSubstr("unit 'odd'"));
    EXPECT_THAT(e.problems()[0].message, HasSubstr("0.0015 s is not an integer multiple"));
    // The loader points at the unit's step_s line through this index.
    EXPECT_EQ(e.problems()[0].unit, 1u);
  }
}

// Guards against: accepting a run that ends between two steps of a unit (its
// last step would go past the stop time). 10 ms is not a multiple of 3 ms.
// Both bad units are reported at once.
TEST(MasterConfig, RefusesADurationThatAUnitStepDoesNotDivide) {
  System system;
  system.Add(std::make_unique<RampSource>("every3ms"), 3 * kMs);
  system.Add(std::make_unique<RampSource>("every2ms"), 2 * kMs);
  system.Add(std::make_unique<RampSource>("every4ms"), 4 * kMs);
  MasterOptions o;
  o.base_step = kMs;
  o.stop = 10 * kMs;
  try {
    Master master(system, o);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.problems().size(), 2u) << e.what();
    EXPECT_THAT(e.problems()[0].message, HasSubstr("unit 'every3ms'"));
    EXPECT_THAT(e.problems()[0].message, HasSubstr("does not divide the duration 0.01 s"));
    EXPECT_THAT(e.problems()[1].message, HasSubstr("unit 'every4ms'"));
    EXPECT_EQ(e.problems()[0].unit, 0u);
    EXPECT_EQ(e.problems()[1].unit, 2u);
  }
}

// Guards against: silently accepting master settings that cannot run: a
// non-positive base step, stop before start, no threads, a duration that is
// not a whole number of base steps. All reported at once.
TEST(MasterConfig, RefusesBadMasterOptions) {
  {
    System system;
    system.Add(std::make_unique<RampSource>("r"));
    MasterOptions o;
    o.base_step = 0;
    o.start = 5 * kMs;
    o.stop = 2 * kMs;
    o.threads = 0;
    try {
      Master master(system, o);
      FAIL() << "expected ConfigError";
    } catch (const ConfigError& e) {
      EXPECT_THAT(e.what(), HasSubstr("master step must be positive"));
      EXPECT_THAT(e.what(), HasSubstr("stop time 0.002 s is before start time 0.005 s"));
      EXPECT_THAT(e.what(), HasSubstr("threads must be at least 1"));
    }
  }
  {
    System system;
    system.Add(std::make_unique<RampSource>("r"));
    MasterOptions o;
    o.base_step = 3 * kMs;
    o.stop = 10 * kMs;
    try {
      Master master(system, o);
      FAIL() << "expected ConfigError";
    } catch (const ConfigError& e) {
      EXPECT_THAT(e.what(), HasSubstr("duration 0.01 s is not a whole number of master steps"));
    }
  }
}

// Guards against: starting with inputs at their declared start values
// instead of the values their sources have at t0. Chain source -> a -> b ->
// c, each y = u with direct feedthrough, declared and connected in reverse so
// that one transfer pass cannot settle it: c.u must equal source.value = 2.5
// (the ramp's offset) after Start(), before any step.
TEST(MasterInitialValues, PropagateThroughAChainOfFeedthroughUnits) {
  for (Algorithm alg : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    System system;
    system.Add(std::make_unique<PassThrough>("c", true));
    system.Add(std::make_unique<PassThrough>("b", true));
    system.Add(std::make_unique<PassThrough>("a", true));
    system.Add(std::make_unique<RampSource>("source", 0.0, 2.5, "1"));
    system.Connect("b.y", "c.u");
    system.Connect("a.y", "b.u");
    system.Connect("source.value", "a.u");
    MasterOptions o;
    o.algorithm = alg;
    o.stop = 10 * kMs;
    Master master(system, o);
    master.Start();
    const auto& c = system.unit(0).variables();
    EXPECT_EQ(master.time(), 0);
    EXPECT_EQ(c.GetReal(*c.Find("u")), 2.5);
    EXPECT_EQ(c.GetReal(*c.Find("y")), 2.5);
    EXPECT_TRUE(master.Finish().ok);
  }
}

// Guards against: a unit that refuses an initial input value being
// reported without its name. The input only arrives during initial value
// propagation (source value 2 > limit 1), after the first Initialize pass.
TEST(MasterInitialValues, UnitThrowingDuringPropagationIsNamed) {
  System system;
  system.Add(std::make_unique<RampSource>("source", 0.0, 2.0, "1"));
  system.Add(std::make_unique<test_units::PickyUnit>("picky", 1.0));
  system.Connect("source.value", "picky.u");
  MasterOptions o;
  o.stop = 10 * kMs;
  Master master(system, o);
  const RunResult r = master.Run();
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.base_steps, 0);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_THAT(r.errors[0].message, HasSubstr("unit 'picky' (Picky) at t = 0 s"));
  EXPECT_THAT(r.errors[0].message, HasSubstr("above its limit"));
}

struct FaultyRun {
  RunResult result;
  std::string csv;
};

FaultyRun RunFaulty(FaultyUnit::Mode mode, TimeNs fail_time, Algorithm alg) {
  System system;
  system.Add(std::make_unique<RampSource>("clock"));
  system.Add(std::make_unique<FaultyUnit>("bad", mode, fail_time));
  std::ostringstream csv;
  CsvRecorder recorder(csv, ResolveProbes(system, {"bad.y"}));
  MasterOptions o;
  o.algorithm = alg;
  o.base_step = kMs;
  o.stop = 20 * kMs;
  Master master(system, o);
  master.AddObserver(&recorder);
  FaultyRun out;
  out.result = master.Run();
  out.csv = csv.str();
  return out;
}

// Guards against: a NaN output propagating silently, being reported without
// saying where, or taking the recorded rows with it. The unit's output for
// t = 5 ms is NaN: the run stops there, the last valid time is 4 ms after 4
// base steps, and the CSV keeps the header and the rows 0 .. 0.004 s.
TEST(MasterGuard, NanOutputStopsTheRunAndNamesUnitVariableAndTime) {
  for (Algorithm alg : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    const FaultyRun run = RunFaulty(FaultyUnit::Mode::kNaN, 5 * kMs, alg);
    EXPECT_FALSE(run.result.ok);
    EXPECT_EQ(run.result.end_time, 4 * kMs);
    EXPECT_EQ(run.result.base_steps, 4);
    ASSERT_EQ(run.result.errors.size(), 1u);
    const std::string& e = run.result.errors[0].message;
    EXPECT_THAT(e, HasSubstr("unit 'bad'"));
    EXPECT_THAT(e, HasSubstr("output 'y'"));
    EXPECT_THAT(e, HasSubstr("nan"));
    EXPECT_THAT(e, HasSubstr("t = 0.005 s"));
    EXPECT_EQ(run.csv, "time,bad.y\n0,0\n0.001,0.001\n0.002,0.002\n0.003,0.003\n0.004,0.004\n");
  }
}

// Guards against: the guard checking only for NaN. An infinite output at
// t = 3 ms is refused in the same way.
TEST(MasterGuard, InfiniteOutputStopsTheRun) {
  const FaultyRun run = RunFaulty(FaultyUnit::Mode::kInf, 3 * kMs, Algorithm::kJacobi);
  EXPECT_FALSE(run.result.ok);
  EXPECT_EQ(run.result.end_time, 2 * kMs);
  ASSERT_EQ(run.result.errors.size(), 1u);
  EXPECT_THAT(run.result.errors[0].message, HasSubstr("output 'y' is inf"));
  EXPECT_THAT(run.result.errors[0].message, HasSubstr("t = 0.003 s"));
}

// Guards against: a failed step being ignored, or reported without the
// unit, the time of the failing step or the cause. The unit fails in the
// step that starts at 7 ms, so 7 base steps completed and the run ends there.
TEST(MasterErrors, UnitReturningErrorStopsTheRunWithNameTimeAndCause) {
  for (Algorithm alg : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    const FaultyRun run = RunFaulty(FaultyUnit::Mode::kError, 7 * kMs, alg);
    EXPECT_FALSE(run.result.ok);
    EXPECT_EQ(run.result.end_time, 7 * kMs);
    EXPECT_EQ(run.result.base_steps, 7);
    ASSERT_EQ(run.result.errors.size(), 1u);
    EXPECT_EQ(run.result.errors[0].message, "unit 'bad' (Faulty) at t = 0.007 s: actuator saturated");
  }
}

// Guards against: an exception escaping the master (or killing a TBB worker)
// instead of ending the run with a report.
TEST(MasterErrors, UnitThrowingStopsTheRunWithNameTimeAndCause) {
  for (Algorithm alg : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    const FaultyRun run = RunFaulty(FaultyUnit::Mode::kThrow, 7 * kMs, alg);
    EXPECT_FALSE(run.result.ok);
    EXPECT_EQ(run.result.end_time, 7 * kMs);
    ASSERT_EQ(run.result.errors.size(), 1u);
    EXPECT_EQ(run.result.errors[0].message, "unit 'bad' (Faulty) at t = 0.007 s: solver diverged");
  }
}

// Guards against: a discarded step being treated as success; a fixed-step
// master cannot retry, so it must stop and say so.
TEST(MasterErrors, DiscardedStepStopsTheRun) {
  const FaultyRun run = RunFaulty(FaultyUnit::Mode::kDiscard, 2 * kMs, Algorithm::kGaussSeidel);
  EXPECT_FALSE(run.result.ok);
  ASSERT_EQ(run.result.errors.size(), 1u);
  EXPECT_THAT(run.result.errors[0].message, HasSubstr("unit 'bad'"));
  EXPECT_THAT(run.result.errors[0].message, HasSubstr("t = 0.002 s"));
  EXPECT_THAT(run.result.errors[0].message, HasSubstr("discarded the step (tolerance not met)"));
}

// Refuses a non-finite input in its step (Unit::InputsFinite).
class StrictSink : public Unit {
 public:
  StrictSink() : Unit("Strict", "strict") { variables().Input("u", "s", &u_, "checked input"); }
  StepResult DoStep(TimeNs t, TimeNs) override {
    ClearError();
    return InputsFinite(t) ? StepResult::kOk : StepResult::kError;
  }

 private:
  double u_ = 0.0;
};

// Guards against: Gauss-Seidel blaming a NaN on the unit that received it.
// The sink steps after the faulty unit and would fail on the NaN input; each
// unit is checked before the next consumes its outputs, so only 'bad' is
// named.
TEST(MasterGuard, GaussSeidelBlamesTheUnitThatMadeTheNaN) {
  System system;
  system.Add(std::make_unique<FaultyUnit>("bad", FaultyUnit::Mode::kNaN, 3 * kMs));
  system.Add(std::make_unique<StrictSink>());
  system.Connect("bad.y", "strict.u");
  MasterOptions o;
  o.algorithm = Algorithm::kGaussSeidel;
  o.stop = 10 * kMs;
  Master master(system, o);
  const RunResult r = master.Run();
  EXPECT_FALSE(r.ok);
  ASSERT_EQ(r.errors.size(), 1u) << r.errors[0].message;
  EXPECT_EQ(r.errors[0].message, "unit 'bad' (Faulty) at t = 0.003 s: output 'y' is nan");
}

// Guards Unit::InputsFinite: a non-finite input fails the step with the
// input's name, its value and the time.
TEST(UnitInputs, NonFiniteInputFailsTheStepByName) {
  StrictSink sink;
  sink.variables().SetReal(*sink.variables().Find("u"), std::numeric_limits<double>::infinity());
  EXPECT_EQ(sink.DoStep(2 * kMs, kMs), StepResult::kError);
  EXPECT_EQ(sink.last_error(), "unit 'strict' (Strict): input 'u' is inf at t = 0.002 s");
}

// A unit whose messages name it, as units used on their own do.
class SelfNamingUnit : public Unit {
 public:
  SelfNamingUnit() : Unit("SelfNaming", "w") {}
  void Initialize() override { throw UnitError(Where() + ": not ready"); }
  StepResult DoStep(TimeNs, TimeNs) override { return StepResult::kOk; }
};

// Guards against: the unit named twice when its own message already names
// it, in any phase (here Initialize, where the master adds the phase).
TEST(MasterErrors, UnitIsNamedOnceWithThePhase) {
  System system;
  system.Add(std::make_unique<SelfNamingUnit>());
  MasterOptions o;
  o.stop = 10 * kMs;
  Master master(system, o);
  const RunResult r = master.Run();
  EXPECT_FALSE(r.ok);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].message, "unit 'w' (SelfNaming) at t = 0 s: initialize failed: not ready");
}

// Guards against: a failure inside a parallel Jacobi step being lost or
// reported without the unit name.
TEST(MasterErrors, FailureInParallelJacobiIsReported) {
  System system;
  system.Add(std::make_unique<RampSource>("clock"));
  system.Add(std::make_unique<FaultyUnit>("bad", FaultyUnit::Mode::kThrow, 3 * kMs));
  system.Add(std::make_unique<RampSource>("other"));
  MasterOptions o;
  o.algorithm = Algorithm::kJacobi;
  o.threads = 2;
  o.stop = 10 * kMs;
  Master master(system, o);
  const RunResult r = master.Run();
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.end_time, 3 * kMs);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].message, "unit 'bad' (Faulty) at t = 0.003 s: solver diverged");
}

// Guards against: Step() advancing past the stop time or after a failure.
TEST(MasterStepwise, StepReturnsFalseAtTheStopTimeAndStaysThere) {
  System system;
  system.Add(std::make_unique<RampSource>("r"));
  MasterOptions o;
  o.stop = 3 * kMs;
  Master master(system, o);
  master.Start();
  EXPECT_TRUE(master.Step());
  EXPECT_TRUE(master.Step());
  EXPECT_FALSE(master.Step());  // reached 3 ms
  EXPECT_EQ(master.time(), 3 * kMs);
  EXPECT_FALSE(master.Step());
  EXPECT_EQ(master.time(), 3 * kMs);
  const RunResult r = master.Finish();
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.base_steps, 3);
  const auto& t = system.unit(0).variables();
  EXPECT_EQ(t.GetReal(*t.Find("value")), NsToSeconds(3 * kMs));
}

// Guards against: the master's own start time being ignored (units stepped
// from 0 instead of `start`). Start 1 s, 2 ms base: calls at 1.000, 1.002 s.
TEST(MasterStepwise, NonZeroStartTime) {
  System system;
  auto& r = static_cast<RampSource&>(system.Add(std::make_unique<RampSource>("r")));
  MasterOptions o;
  o.base_step = 2 * kMs;
  o.start = 1000 * kMs;
  o.stop = 1004 * kMs;
  Master master(system, o);
  ASSERT_TRUE(master.Run().ok);
  ASSERT_EQ(r.calls.size(), 2u);
  EXPECT_EQ(r.calls[0].t, 1000 * kMs);
  EXPECT_EQ(r.calls[1].t, 1002 * kMs);
  EXPECT_EQ(r.calls[1].dt, 2 * kMs);
}

}  // namespace
}  // namespace linesim::cosim

namespace linesim::cosim {
namespace {

// Guards the FMI feedthrough contract at communication points: with Jacobi,
// a chain source -> a -> b -> sink of direct-feedthrough pass-throughs must
// deliver the source's value of the same communication point (the chain is
// algebraic: y = u), not one stale step per unit. Expected from the rule:
// the sink sees ramp(t) = t at each of its steps t. Gauss-Seidel steps the
// source first, so the sink sees ramp(t + h).
TEST(MasterFeedthrough, OutputsFollowInputsSetAtTheSameCommunicationPoint) {
  for (Algorithm alg : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    System system;
    auto* sink = static_cast<test_units::RecordingSink*>(
        &system.Add(std::make_unique<test_units::RecordingSink>("sink", "s")));
    system.Add(std::make_unique<test_units::PassThrough>("b", true, "s"));
    system.Add(std::make_unique<test_units::PassThrough>("a", true, "s"));
    system.Add(std::make_unique<test_units::RampSource>("source"));
    system.Connect("source.value", "a.u");
    system.Connect("a.y", "b.u");
    system.Connect("b.y", "sink.value");
    MasterOptions o;
    o.algorithm = alg;
    o.base_step = kMs;
    o.stop = 5 * kMs;
    Master master(system, o);
    ASSERT_TRUE(master.Run().ok);
    ASSERT_EQ(sink->seen.size(), 5u);
    for (std::size_t k = 0; k < 5; ++k) {
      const double t = static_cast<double>(k) * 1e-3;
      const double expected = alg == Algorithm::kJacobi ? t : t + 1e-3;
      EXPECT_DOUBLE_EQ(sink->seen[k], expected) << "step " << k;
    }
  }
}

// Guards against: the algorithm names of scenarios and summaries drifting
// apart, or a typo being read as an algorithm.
TEST(ParseAlgorithm, NamesReadBackAndOthersAreRefused) {
  EXPECT_EQ(AlgorithmNames(), (std::vector<std::string>{"jacobi", "gauss_seidel"}));
  for (const Algorithm a : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    Algorithm parsed = a == Algorithm::kJacobi ? Algorithm::kGaussSeidel : Algorithm::kJacobi;
    EXPECT_TRUE(ParseAlgorithm(ToString(a), &parsed)) << ToString(a);
    EXPECT_EQ(parsed, a);
  }
  Algorithm a = Algorithm::kJacobi;
  EXPECT_FALSE(ParseAlgorithm("gauss-seidel", &a));
  EXPECT_FALSE(ParseAlgorithm("Jacobi", &a));
  EXPECT_EQ(a, Algorithm::kJacobi);
}

}  // namespace
}  // namespace linesim::cosim
