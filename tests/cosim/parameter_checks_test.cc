#include "cosim/parameter_checks.h"

#include <gtest/gtest.h>

#include <limits>

namespace linesim::cosim {
namespace {

// Guards the shared wording and indexing of parameter problems: every unit's
// CheckParameters relies on it, and the loader turns variable + index into
// the key path of the bad value.
TEST(ParameterChecks, RulesNameTheVariableTheElementAndTheValue) {
  ParameterChecks c;
  c.Positive("mass", 0.0);
  c.NonNegative("friction", std::vector<double>{0.0, -1.0, 2.0});
  c.Finite("x", std::numeric_limits<double>::infinity());
  c.Check(
      "eta", 1.5, [](double v) { return v > 0.0 && v <= 1.0; }, "must be in (0, 1]");
  c.Positive("fine", 3.0);
  const auto problems = c.Take();
  ASSERT_EQ(problems.size(), 4u);
  EXPECT_EQ(problems[0].variable, "mass");
  EXPECT_FALSE(problems[0].index.has_value());
  EXPECT_EQ(problems[0].message, "must be positive and finite, got 0");
  EXPECT_EQ(problems[1].variable, "friction");
  EXPECT_EQ(problems[1].index, 1u);
  EXPECT_EQ(problems[1].message, "must be zero or positive and finite, got -1");
  EXPECT_EQ(problems[2].message.rfind("must be finite, got ", 0), 0u);
  EXPECT_EQ(problems[3].message, "must be in (0, 1], got 1.5");
}

// Guards Unit::ThrowIfBadParameters: one error naming the unit and every
// problem, as Initialize reports them.
class Checked : public Unit {
 public:
  Checked() : Unit("checked", "u") {}
  std::vector<ParameterProblem> CheckParameters() const override {
    ParameterChecks c;
    c.Positive("a", -1.0);
    c.Positive("b", std::vector<double>{1.0, 0.0});
    return c.Take();
  }
  void Initialize() override { ThrowIfBadParameters(); }
  StepResult DoStep(TimeNs, TimeNs) override { return StepResult::kOk; }
};

TEST(ParameterChecks, UnitThrowsEveryProblemAtOnce) {
  Checked u;
  try {
    u.Initialize();
    FAIL() << "no error";
  } catch (const UnitError& e) {
    EXPECT_STREQ(e.what(),
                 "unit 'u' (checked): parameter 'a' must be positive and finite, got -1; "
                 "parameter 'b[1]' must be positive and finite, got 0");
  }
}

}  // namespace
}  // namespace linesim::cosim
