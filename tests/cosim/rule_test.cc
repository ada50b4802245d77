// Rules declared with a parameter (FMI's min/max and more), the default
// Unit::CheckParameters that walks them, and the variability the table's
// setters enforce.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "cosim/unit.h"

namespace linesim::cosim {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Guards issue 37: a safety_field restart_delay of 9.2e9 s or more restarted
// the robot at once, as a delay of 0 (llround(x * 1e9) overflowed int64).
// Every Real parameter in seconds gets the time's rule from the table,
// whatever the unit declared: finite, within +-4.6e9 s (cosim::
// kMaxTimeSeconds: a time plus a duration fits int64 nanoseconds), no
// non-zero value below 1 ns; a value the limit refuses is told the limit.
TEST(Rule, EveryParameterInSecondsIsATime) {
  struct Timed : Unit {
    Timed() : Unit("timed", "t") {
      variables().Parameter("delay", "s", &delay, "declared >= 0", Rule::NonNegative());
      variables().Parameter("period", "s", &period, "declared > 0", Rule::Positive());
      variables().Parameter("offset", "s", &offset, "declared without a rule");
      variables().Parameter("pauses", "s", &pauses, "an array", Rule::NonNegative());
      variables().Parameter("window", "s", &window, "bounded tighter", Rule::Range(0, 1));
      variables().Parameter("length", "m", &length, "not a time", Rule::NonNegative());
    }
    StepResult DoStep(TimeNs, TimeNs) override { return StepResult::kOk; }
    double delay = 2.0, period = 0.04, offset = 0.0, window = 0.2, length = 1.0;
    std::vector<double> pauses = {0.0, 6.0};
  };
  Timed u;
  EXPECT_TRUE(u.CheckParameters().empty());
  const auto& t = u.variables();
  const auto rule = [&](const char* name) { return t.info(*t.Find(name)).rule; };
  // The bounds are the limit's where the unit left them open (inspect and
  // FMI's min/max show them).
  EXPECT_EQ(rule("delay").Text(), "[0, 4.6e+09]");
  EXPECT_EQ(rule("offset").Text(), "[-4.6e+09, 4.6e+09]");
  EXPECT_EQ(rule("window").Text(), "[0, 1]");
  EXPECT_EQ(rule("length").Text(), ">= 0");
  EXPECT_EQ(rule("delay").upper(), kMaxTimeSeconds);

  // A huge value, the limit named.
  const auto huge = rule("delay").Violation(1e10);
  ASSERT_TRUE(huge);
  EXPECT_NE(huge->find("must be in [0, 4.6e+09] (4.6e9 s is the longest time linesim "
                       "represents: int64 nanoseconds"),
            std::string::npos)
      << *huge;
  EXPECT_NE(huge->find("got 1e+10"), std::string::npos) << *huge;
  EXPECT_FALSE(rule("delay").Violation(kMaxTimeSeconds));
  EXPECT_TRUE(rule("delay").Violation(std::nextafter(kMaxTimeSeconds, kInf)));
  EXPECT_TRUE(rule("offset").Violation(-1e10));
  EXPECT_FALSE(rule("offset").Violation(-1.0));
  // A negative where the unit said so, NaN and inf always.
  EXPECT_EQ(rule("delay").Violation(-1.0), "must be in [0, 4.6e+09], got -1");
  EXPECT_TRUE(rule("offset").Violation(kNan));
  EXPECT_TRUE(rule("offset").Violation(kInf));
  // Below the resolution: it would round to 0 ns.
  const auto tiny = rule("period").Violation(1e-12);
  ASSERT_TRUE(tiny);
  EXPECT_NE(tiny->find("must be at least 1e-09 in magnitude (1 ns is the time resolution"),
            std::string::npos)
      << *tiny;
  EXPECT_NE(rule("delay").Violation(1e-12)->find("must be 0 or at least 1e-09"), std::string::npos);
  EXPECT_FALSE(rule("delay").Violation(0.0));
  EXPECT_FALSE(rule("delay").Violation(1e-9));

  // CheckParameters, element by element.
  u.delay = 1e10;
  u.pauses = {1.0, 9.3e9};
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].variable, "delay");
  EXPECT_EQ(problems[1].variable, "pauses");
  EXPECT_EQ(problems[1].index, 1u);
  // A rule set later (by a helper) is a time's too.
  double later = 0.0;
  VariableTable table;
  const ValueRef ref = table.Parameter("later", "s", &later, "set below");
  table.SetRule(ref, Rule::Positive());
  EXPECT_EQ(table.info(ref).rule.Text(), "(0, 4.6e+09]");
}

// Guards the counts' rule (an encoder's counts per revolution, which its
// unit turns into integer counts): finite and within +-2^53, the largest
// count a Real carries exactly, named when refused.
TEST(Rule, CountsStayWithinWhatARealCarriesExactly) {
  const Rule cpr = Rule::Positive().NoDefault().Count();
  EXPECT_FALSE(cpr.Violation(16384.0));
  EXPECT_FALSE(cpr.Violation(kMaxExactCount));
  const auto huge = cpr.Violation(1e17);
  ASSERT_TRUE(huge);
  EXPECT_NE(huge->find("2^53 is the largest count a Real carries exactly"), std::string::npos)
      << *huge;
  EXPECT_EQ(cpr.Violation(-1.0), "must be in (0, 9007199254740992], got -1");
  EXPECT_EQ(cpr.Violation(kNan), "must be set (robot-specific: no default)");
  EXPECT_TRUE(cpr.Violation(kInf));
  EXPECT_TRUE(cpr.required());
  // No resolution: a small count per revolution is a count.
  EXPECT_FALSE(cpr.Violation(1e-12));
}

// Guards the one wording of a broken rule: what was expected, then the
// value, for every kind of rule; and the text inspect prints.
TEST(Rule, WordsWhatWasExpectedAndTheValue) {
  EXPECT_EQ(Rule::Positive().Violation(-1.0), "must be > 0, got -1");
  EXPECT_EQ(Rule::Positive().Violation(0.0), "must be > 0, got 0");
  EXPECT_EQ(Rule::Positive().Violation(kInf), "must be finite and > 0, got inf");
  EXPECT_FALSE(Rule::Positive().Violation(1e-300));
  EXPECT_EQ(Rule::NonNegative().Violation(-0.5), "must be >= 0, got -0.5");
  EXPECT_FALSE(Rule::NonNegative().Violation(0.0));
  const Rule eta = Rule::Range(0, false, 1, true);
  EXPECT_EQ(eta.Violation(0.0), "must be in (0, 1], got 0");
  EXPECT_EQ(eta.Violation(1.5), "must be in (0, 1], got 1.5");
  EXPECT_FALSE(eta.Violation(1.0));
  EXPECT_EQ(Rule::Range(-1, 1).Violation(kNan), "must be finite and in [-1, 1], got nan");
  EXPECT_EQ(Rule::AtMost(2, false).Violation(2.0), "must be < 2, got 2");
  EXPECT_EQ(Rule::Finite().Violation(-kInf), "must be finite, got -inf");
  EXPECT_FALSE(Rule().Violation(kNan));
  EXPECT_EQ(Rule::Required().Violation(kNan), "must be set (robot-specific: no default)");
  EXPECT_EQ(Rule::Positive().NoDefault().Violation(kNan),
            "must be set (robot-specific: no default)");
  EXPECT_EQ(Rule::Positive().NoDefault().Violation(-1.0), "must be > 0, got -1");
  EXPECT_EQ(Rule::OneOf({"full", "current_only"}).Violation(std::string("half")),
            "must be one of: full, current_only, got 'half'");
  EXPECT_EQ(Rule::Required().Violation(std::string()), "must be set (robot-specific: no default)");
  EXPECT_EQ(Rule::OneOf({1, 2, 4}).Violation(std::int64_t{3}), "must be one of: 1, 2, 4, got 3");
  EXPECT_EQ(Rule::AtLeast(1).Violation(std::int64_t{0}), "must be >= 1, got 0");

  EXPECT_EQ(Rule::Positive().Text(), "> 0");
  EXPECT_EQ(Rule::Range(0, 1).Text(), "[0, 1]");
  EXPECT_EQ(eta.Text(), "(0, 1]");
  EXPECT_EQ(Rule::Finite().Text(), "finite");
  EXPECT_EQ(Rule::OneOf({"full", "current_only"}).Text(), "one of: full, current_only");
  EXPECT_EQ(Rule::Required().Text(), "required");
  EXPECT_EQ(Rule::Positive().NoDefault().Text(), "required, > 0");
  EXPECT_EQ(Rule().Text(), "");
  EXPECT_THROW(Rule::Range(1, 0), std::logic_error);
  EXPECT_THROW(Rule::AtLeast(kNan), std::logic_error);
}

class Ruled : public Unit {
 public:
  Ruled() : Unit("ruled", "u") {
    auto& v = variables();
    v.Parameter("mass", "kg", &mass_, "total mass", Rule::Positive());
    v.Parameter("wheel_x", "m", &wheel_x_, "wheel positions", Rule::Required());
    v.Parameter("mode", &mode_, "how", Rule::OneOf({"full", "current_only"}));
    v.Parameter("count", &count_, "how many", Rule::OneOf({1, 2, 4}));
    v.Parameter("gain", "1", &gain_, "tuned between steps", Rule::NonNegative(),
                Variability::kTunable);
    v.Parameter("free", "1", &free_, "no rule");
    v.Output("y", "1", &y_, "output", {});
  }
  StepResult DoStep(TimeNs, TimeNs) override { return StepResult::kOk; }
  void Initialize() override { ThrowIfBadParameters(); }

  double mass_ = 1.0;
  std::vector<double> wheel_x_ = std::vector<double>(3, kNan);
  std::string mode_ = "full";
  std::int64_t count_ = 2;
  double gain_ = 0.5;
  double free_ = kNan;
  double y_ = 0.0;
};

// Guards the default CheckParameters: every rule of every parameter, each
// element of an array on its own, in declaration order; ThrowIfBadParameters
// names them all.
TEST(Rule, DefaultCheckParametersReportsEveryBrokenRule) {
  Ruled u;
  auto& t = u.variables();
  t.SetValue(*t.Find("mass"), -1.0);
  t.SetValue(*t.Find("wheel_x"), std::vector<double>{0.3, 0.3, kNan});
  t.SetValue(*t.Find("mode"), std::string("half"));
  t.SetValue(*t.Find("count"), std::int64_t{3});
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 4u);
  EXPECT_EQ(problems[0].variable, "mass");
  EXPECT_EQ(problems[0].message, "must be > 0, got -1");
  EXPECT_EQ(problems[1].variable, "wheel_x");
  EXPECT_EQ(problems[1].index, 2u);
  EXPECT_EQ(problems[1].message, "must be set (robot-specific: no default)");
  EXPECT_EQ(problems[2].variable, "mode");
  EXPECT_EQ(problems[3].variable, "count");
  try {
    u.Initialize();
    FAIL() << "no error";
  } catch (const UnitError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unit 'u' (ruled): parameter 'mass' must be > 0, got -1; "
                       "parameter 'wheel_x[2]' must be set (robot-specific: no default)"),
              std::string::npos)
        << msg;
  }
  t.SetValue(*t.Find("mass"), 2.0);
  t.SetValue(*t.Find("wheel_x"), 0.3);
  t.SetValue(*t.Find("mode"), std::string("current_only"));
  t.SetValue(*t.Find("count"), std::int64_t{4});
  EXPECT_TRUE(u.CheckParameters().empty());
}

// Guards the check the loader and sweeps use before running: a value is
// judged against the declared rule without setting it.
TEST(Rule, CheckRuleJudgesAValueAtItsKey) {
  Ruled u;
  const auto& t = u.variables();
  const VariableInfo& mass = t.info(*t.Find("mass"));
  EXPECT_TRUE(CheckRule(mass, 2.0).empty());
  EXPECT_EQ(CheckRule(mass, std::int64_t{-2}).at(0).message, "must be > 0, got -2");
  const VariableInfo& wheel_x = t.info(*t.Find("wheel_x"));
  const auto list = CheckRule(wheel_x, std::vector<double>{1, kInf, kNan});
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].index, 1u);
  EXPECT_EQ(list[1].index, 2u);
  // A scalar for a list stands for every element: one problem, no index.
  const auto scalar = CheckRule(wheel_x, kNan);
  ASSERT_EQ(scalar.size(), 1u);
  EXPECT_FALSE(scalar[0].index);
  // Wrong types are SetValue's business.
  EXPECT_TRUE(CheckRule(mass, std::string("x")).empty());
  EXPECT_TRUE(CheckRule(t.info(*t.Find("free")), kNan).empty());
  EXPECT_EQ(t.info(*t.Find("mode")).rule.Text(), "one of: full, current_only");
}

// Guards declarations that cannot mean anything: a rule for another type, a
// required parameter with a default, a rule on a signal.
TEST(Rule, MisdeclaredRulesAreLogicErrors) {
  struct Bad : Unit {
    Bad() : Unit("bad", "b") {}
    StepResult DoStep(TimeNs, TimeNs) override { return StepResult::kOk; }
    double x = 1.0;
    bool flag = false;
    std::string s = "a";
    std::int64_t n = 1;
  };
  Bad b;
  auto& v = b.variables();
  EXPECT_THROW(v.Parameter("x", "1", &b.x, "", Rule::OneOf({"a"})), std::logic_error);
  EXPECT_THROW(v.Parameter("x2", "1", &b.x, "", Rule::Required()), std::logic_error);
  EXPECT_THROW(v.Parameter("s", &b.s, "", Rule::Positive()), std::logic_error);
  EXPECT_THROW(v.Parameter("n", &b.n, "", Rule::Required()), std::logic_error);
  const ValueRef flag = v.Parameter("flag", &b.flag, "");
  EXPECT_THROW(v.SetRule(flag, Rule::Positive()), std::logic_error);
  const ValueRef out = v.Output("o", "1", &b.x, "", {});
  EXPECT_THROW(v.SetRule(out, Rule::Positive()), std::logic_error);
}

// Guards variability: a fixed parameter is set before the run only, a
// tunable one also between steps, a constant never from outside; inputs stay
// writable; RestoreState still restores everything.
TEST(Variability, FixedParametersAreReadOnlyOnceLockedAndRestoreStillWorks) {
  Ruled u;
  auto& t = u.variables();
  const ValueRef mass = *t.Find("mass");
  const ValueRef gain = *t.Find("gain");
  t.SetReal(mass, 3.0);  // before the run: fine
  const UnitState saved = u.SaveState();
  t.Lock();
  EXPECT_TRUE(t.locked());
  try {
    t.SetReal(mass, 4.0);
    FAIL() << "a fixed parameter changed after initialization";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("parameter 'mass' is fixed"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(t.SetValue(mass, 4.0), std::logic_error);
  EXPECT_THROW(t.SetRealElement(*t.Find("wheel_x"), 0, 1.0), std::logic_error);
  EXPECT_THROW(t.SetString(*t.Find("mode"), "full"), std::logic_error);
  EXPECT_THROW(t.SetInteger(*t.Find("count"), 1), std::logic_error);
  EXPECT_EQ(t.GetReal(mass), 3.0);
  t.SetReal(gain, 0.7);          // tunable
  t.SetReal(*t.Find("y"), 1.0);  // the unit's own output
  u.mass_ = 9.0;                 // the unit may still do what it likes with its members
  u.RestoreState(saved);
  EXPECT_EQ(t.GetReal(mass), 3.0);
  EXPECT_EQ(t.GetReal(gain), 0.5);
  EXPECT_THROW(t.SetReal(mass, 4.0), std::logic_error);  // still locked

  struct WithConstant : Unit {
    WithConstant() : Unit("const", "c") {
      variables().Parameter("g", "m/s2", &g, "gravity", Variability::kConstant);
    }
    StepResult DoStep(TimeNs, TimeNs) override { return StepResult::kOk; }
    double g = 9.81;
  };
  WithConstant c;
  try {
    c.variables().SetValue(0, 1.0);
    FAIL() << "a constant was set";
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "parameter 'g' is a constant of the unit: it cannot be set");
  }
  c.g = 1.0;
  c.RestoreState(WithConstant().SaveState());
  EXPECT_EQ(c.g, 9.81);
}

}  // namespace
}  // namespace linesim::cosim
