// Unit::SaveState / RestoreState: a restored unit continues bit for bit.

#include "cosim/unit.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

#include "tests/cosim/test_units.h"

namespace linesim::cosim {
namespace {

using test_units::CouplingUnit;
using test_units::Mass1Unit;
using test_units::PortsUnit;
using test_units::TwoMassParams;
using ::testing::HasSubstr;

constexpr TimeNs kStep = 2'000'000;  // 2 ms

// The two-mass pair stepped by hand (Jacobi exchange), so that the test
// depends only on the Unit interface. Returns x1, v1, force after each step.
struct Pair {
  Pair() : mass1(TwoMassParams{}), coupling(TwoMassParams{}) {
    const auto& t1 = mass1.variables();
    const auto& t2 = coupling.variables();
    x = *t1.Find("x");
    v = *t1.Find("v");
    force_in = *t1.Find("force");
    x1_in = *t2.Find("x1");
    v1_in = *t2.Find("v1");
    force = *t2.Find("force");
  }
  void Exchange() {
    coupling.variables().SetReal(x1_in, mass1.variables().GetReal(x));
    coupling.variables().SetReal(v1_in, mass1.variables().GetReal(v));
    mass1.variables().SetReal(force_in, coupling.variables().GetReal(force));
  }
  std::vector<double> Steps(int n, TimeNs& t) {
    std::vector<double> out;
    for (int i = 0; i < n; ++i, t += kStep) {
      Exchange();
      EXPECT_EQ(mass1.DoStep(t, kStep), StepResult::kOk);
      EXPECT_EQ(coupling.DoStep(t, kStep), StepResult::kOk);
      out.push_back(mass1.variables().GetReal(x));
      out.push_back(mass1.variables().GetReal(v));
      out.push_back(coupling.variables().GetReal(force));
    }
    return out;
  }
  Mass1Unit mass1;
  CouplingUnit coupling;
  ValueRef x, v, force_in, x1_in, v1_in, force;
};

std::vector<std::uint64_t> Bits(const std::vector<double>& v) {
  std::vector<std::uint64_t> out;
  for (double d : v) out.push_back(std::bit_cast<std::uint64_t>(d));
  return out;
}

// Guards against: state that SaveState misses (mass 1 keeps its integrator
// state outside the variable table, mass 2 inside it as locals; the inputs
// held for the next step are variables too). Save, step 50, restore, step 50
// again: the outputs must be identical bit for bit (the design's promise).
TEST(UnitState, SaveStepRestoreStepIsBitIdentical) {
  Pair p;
  p.mass1.Initialize();
  p.coupling.Initialize();
  TimeNs t = 0;
  p.Steps(25, t);  // move away from the initial state
  const UnitState s1 = p.mass1.SaveState();
  const UnitState s2 = p.coupling.SaveState();
  const TimeNs t_saved = t;
  const auto first = p.Steps(50, t);
  p.mass1.RestoreState(s1);
  p.coupling.RestoreState(s2);
  t = t_saved;
  const auto second = p.Steps(50, t);
  EXPECT_EQ(Bits(first), Bits(second));
}

// Guards against: a state that only works in the unit that saved it. A
// fresh pair restored from another pair's snapshot continues exactly like it.
TEST(UnitState, RestoreIntoAnotherInstanceContinuesIdentically) {
  Pair original;
  original.mass1.Initialize();
  original.coupling.Initialize();
  TimeNs t = 0;
  original.Steps(30, t);
  Pair copy;
  copy.mass1.RestoreState(original.mass1.SaveState());
  copy.coupling.RestoreState(original.coupling.SaveState());
  TimeNs t_copy = t;
  EXPECT_EQ(Bits(original.Steps(40, t)), Bits(copy.Steps(40, t_copy)));
}

// Guards against: a snapshot saved with every variable type (real, integer,
// boolean, string, real array) not round-tripping through GetValue/SetValue.
TEST(UnitState, AllVariableTypesRoundTrip) {
  PortsUnit a("a");
  PortsUnit b("b");
  auto& ta = a.variables();
  ta.SetValue(*ta.Find("count"), std::int64_t{-42});
  ta.SetValue(*ta.Find("flag"), true);
  ta.SetValue(*ta.Find("label"), std::string("belt 3"));
  ta.SetValue(*ta.Find("scan"), std::vector<double>{0.1, 0.2, 0.3});
  ta.SetValue(*ta.Find("internal"), 1e-300);
  b.RestoreState(a.SaveState());
  for (const auto& info : ta.infos()) {
    EXPECT_EQ(b.variables().GetValue(info.ref), ta.GetValue(info.ref)) << info.name;
  }
}

// Guards against: restoring a snapshot of another unit type or of another
// size, which would assign variables by position into the wrong meaning.
// The message names the unit.
TEST(UnitState, RestoringAStateOfTheWrongSizeThrows) {
  Mass1Unit mass1(TwoMassParams{});
  CouplingUnit coupling(TwoMassParams{});
  UnitState truncated = mass1.SaveState();  // right type, one variable short
  truncated.variables.pop_back();
  try {
    mass1.RestoreState(truncated);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("state of " + std::to_string(truncated.variables.size()) +
                                    " variables restored into unit 'mass1'"));
  }
  UnitState empty;  // of the right type, so that the size rule refuses it
  empty.type_name = coupling.type_name();
  EXPECT_THROW(coupling.RestoreState(empty), std::invalid_argument);
  // Same variable count (8), other type: refused before anything is written.
  const UnitState before = mass1.SaveState();
  try {
    mass1.RestoreState(coupling.SaveState());
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("restored into unit 'mass1'"));
  }
  EXPECT_EQ(mass1.SaveState().variables, before.variables);
}

// Guards against: a unit's internal part accepting a truncated snapshot
// (mass 1 needs its two integrator states).
TEST(UnitState, RestoringATruncatedInternalStateThrows) {
  Mass1Unit mass1(TwoMassParams{});
  UnitState s = mass1.SaveState();
  s.reals.pop_back();
  EXPECT_THROW(mass1.RestoreState(s), std::invalid_argument);
}

}  // namespace
}  // namespace linesim::cosim

namespace linesim::cosim {
namespace {

// A unit that converts its inputs as units do: a scan's time in seconds to
// nanoseconds, an encoder's position in counts to an integer.
struct Converting : Unit {
  Converting() : Unit("converting", "c") {
    variables().Input("scan_time", "s", &scan_time, "a time in seconds");
    variables().Input("position", "1", &position, "counts");
  }
  StepResult DoStep(TimeNs t, TimeNs) override {
    scan_ns = InputTimeNs(scan_time, "scan_time");
    count = static_cast<std::int64_t>(CheckCount(position, "position"));
    Warn(t, "stepped");
    return StepResult::kOk;
  }
  double scan_time = 0.0, position = 0.0;
  TimeNs scan_ns = 0;
  std::int64_t count = 0;
};

// Guards issue 37 for signals: a time or a count a unit turns into an
// integer (a match's time, an encoder's counts) was cast unchecked
// (undefined beyond int64); now the step fails naming the unit and the
// variable, and the limit.
TEST(UnitConversions, TimesAndCountsOutsideTheirRangeNameTheVariable) {
  Converting u;
  u.scan_time = 1.5;
  u.position = 123.0;
  EXPECT_EQ(u.DoStep(0, 1), StepResult::kOk);
  EXPECT_EQ(u.scan_ns, 1'500'000'000);
  EXPECT_EQ(u.count, 123);
  for (double bad : {1e10, -1e10, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity(), 1e-12}) {
    u.scan_time = bad;
    try {
      u.DoStep(0, 1);
      FAIL() << "accepted scan_time " << bad;
    } catch (const UnitError& e) {
      EXPECT_EQ(e.variable(), "scan_time");
      EXPECT_THAT(e.what(), HasSubstr("unit 'c' (converting): 'scan_time' = "));
    }
  }
  u.scan_time = 1e10;
  try {
    u.DoStep(0, 1);
  } catch (const UnitError& e) {
    EXPECT_THAT(e.what(), HasSubstr("beyond +-4.6e9 s, the longest time linesim represents"));
  }
  u.scan_time = 0.0;
  for (double bad : {1e17, -1e17, std::numeric_limits<double>::quiet_NaN()}) {
    u.position = bad;
    try {
      u.DoStep(0, 1);
      FAIL() << "accepted position " << bad;
    } catch (const UnitError& e) {
      EXPECT_EQ(e.variable(), "position");
      EXPECT_THAT(e.what(), HasSubstr("beyond +-2^53"));
    }
  }
}

// Guards the warnings' bound: a unit warning every step keeps
// kMaxWarnings of them, the last saying how many more there were.
TEST(UnitWarnings, KeptInOrderAndBounded) {
  Converting u;
  for (TimeNs t = 0; t < 25; ++t) u.DoStep(t * 1'000'000, 1);
  const auto& w = u.warnings();
  ASSERT_EQ(w.size(), 20u);  // Unit::kMaxWarnings
  EXPECT_EQ(w.front(), "at t = 0 s: stepped");
  EXPECT_EQ(w[1], "at t = 0.001 s: stepped");
  EXPECT_EQ(w.back(), "and 6 more warnings like the ones before");
}

}  // namespace
}  // namespace linesim::cosim
