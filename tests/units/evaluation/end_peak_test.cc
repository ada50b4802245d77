#include "units/evaluation/end_peak.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace linesim::evaluation {
namespace {

constexpr cosim::TimeNs kStep = 1'000'000;

// Guards the window: currents before the path's last `window` metres never
// count (the climb or the start's acceleration are not the approach), the
// largest |value| of any signal inside it does, negative ones included, and
// the peak holds after the robot stops.
TEST(EndPeakUnit, PeakOnlyInsideTheWindow) {
  EndPeakUnit u("peak", 2);
  auto& v = u.variables();
  const auto set = [&](double remaining, std::vector<double> values) {
    v.SetReal(*v.Find("remaining"), remaining);
    v.SetRealArray(*v.Find("values"), values);
  };
  set(5.0, {30.0, -40.0});
  u.Initialize();
  EXPECT_DOUBLE_EQ(v.GetReal(*v.Find("peak")), 0.0);
  EXPECT_FALSE(v.GetBoolean(*v.Find("entered")));
  cosim::TimeNs t = 0;
  ASSERT_EQ(u.DoStep(t, kStep), cosim::StepResult::kOk);
  EXPECT_DOUBLE_EQ(v.GetReal(*v.Find("peak")), 0.0);
  set(1.9, {3.0, -7.5});
  ASSERT_EQ(u.DoStep(t += kStep, kStep), cosim::StepResult::kOk);
  EXPECT_DOUBLE_EQ(v.GetReal(*v.Find("peak")), 7.5);
  EXPECT_TRUE(v.GetBoolean(*v.Find("entered")));
  set(0.0, {1.0, 2.0});
  ASSERT_EQ(u.DoStep(t += kStep, kStep), cosim::StepResult::kOk);
  EXPECT_DOUBLE_EQ(v.GetReal(*v.Find("peak")), 7.5);
}

// Guards the window's edge and its parameter: exactly `window` metres left
// counts.
TEST(EndPeakUnit, WindowIsAParameter) {
  EndPeakUnit u("peak", 1);
  auto& v = u.variables();
  v.SetReal(*v.Find("window"), 0.5);
  v.SetReal(*v.Find("remaining"), 0.5);
  v.SetRealArray(*v.Find("values"), std::vector<double>{-2.0});
  u.Initialize();
  EXPECT_DOUBLE_EQ(v.GetReal(*v.Find("peak")), 2.0);
}

// Guards against a NaN current passing as "no peak".
TEST(EndPeakUnit, NonFiniteInputFailsTheStep) {
  EndPeakUnit u("peak", 1);
  auto& v = u.variables();
  u.Initialize();
  v.SetRealArray(*v.Find("values"), std::vector<double>{std::nan("")});
  EXPECT_EQ(u.DoStep(0, kStep), cosim::StepResult::kError);
}

}  // namespace
}  // namespace linesim::evaluation
