// The shipped paper-1 scenarios, run end to end through the real units
// (belt, ODE chassis, CVODE motors, controllers) with compensation on (the
// paper's modified system, Algorithm 1) and off (the nominal system).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "tests/scenarios/run_scenario.h"

namespace linesim {
namespace {

// Seeds per run: every bound below must hold for each of them (the seed
// draws the belt's speed variation, the only random input of these runs'
// control loops); the spreads quoted are min / median / max over them.
constexpr int kSeeds = 8;

// The shipped files run the robot's sensors beside the ground-truth control;
// nothing reads them here, so they are off (half the time; the control's
// metrics are the same to the last bit: every metric of cross_line at seed
// 3 and of hold_on_belt and hold_straddle at seed 5, measured both ways).
const std::string kNoSensors = "sensors.default=false";

test_scenarios::SeedRuns RunScenario(const std::string& name, std::vector<std::string> sets,
                                     int seeds = kSeeds) {
  sets.push_back(kNoSensors);
  return test_scenarios::RunSeeds(test_scenarios::Shipped(name), sets, seeds);
}

// The path follower's gains (units/control defaults): cross-track and
// position feedback k = 1/s. Without compensation the belt is an unmodelled
// disturbance velocity v that a proportional loop can only cancel with a
// standing error v/k: the analytic yardstick of the nominal system below.
constexpr double kGain = 1.0;

// Paper 1, Sec. VI-B: crossing a line at 10 cm/s, the modified system stays
// within 4 cm of the path; the nominal one deviates "significantly". The
// robot is on the belt for about (2 m + 1.03 m) / 0.3 m/s = 10 s, ten time
// constants of the loop, so the nominal deviation nears v/k = 0.10 m (less
// the part of the time only some wheels are on the belt). Both arrive: the
// path is 4 m long.
//
// The factor between the two: with compensation a wheel's change of surface
// is seen at most one control period T = 20 ms late, so each of the 4 wheel
// transitions at an edge (front pair, then rear pair, entering and leaving)
// lets the belt carry the robot at most v T = 2 mm before the loop (1/k =
// 1 s) takes it back: at most 4 v T = 8 mm in all. The nominal deviation is
// at least 0.5 v/k = 50 mm, more than 6 times that; a factor 3 keeps half
// of the margin for the contact dynamics.
//
// Seeds 1..8: max_path_deviation_m compensated 0.0047 / 0.0051 / 0.0056,
// nominal 0.0930 / 0.0978 / 0.1012 (the nominal's upper bound, 1.2 v/k =
// 0.12, is the analytic limit v (1 + 10 %) / k plus 10 % for the loop's
// lag: the loop nears v / k by design, so the margin is 16 %, not 20);
// final_progress_m 3.9807 / 3.9809 / 3.9811 (both).
TEST(Paper1Scenarios, CrossLineCompensatedStaysWithin4cmNominalDoesNot) {
  const auto on = RunScenario("cross_line", {"control.compensation=true"});
  const auto off = RunScenario("cross_line", {"control.compensation=false"});
  const double v_over_k = 0.10 / kGain;
  EXPECT_LT(on["max_path_deviation_m"].max(), 0.04);
  EXPECT_GT(off["max_path_deviation_m"].min(), 0.04);
  EXPECT_GT(off["max_path_deviation_m"].min(), 0.5 * v_over_k);
  EXPECT_LT(off["max_path_deviation_m"].max(), 1.2 * v_over_k);  // +-10 % belt speed
  for (std::size_t i = 0; i < on.seeds.size(); ++i) {
    EXPECT_GT(off["max_path_deviation_m"].values[i], 3.0 * on["max_path_deviation_m"].values[i])
        << "seed " << on.seeds[i];
  }
  EXPECT_GT(on["final_progress_m"].min(), 3.9);
  EXPECT_GT(off["final_progress_m"].min(), 3.9);
  // Paper 1's judgement (Fig. 5 and 6): within 4 cm all the way and across.
  EXPECT_EQ(on["crossing_success"].min(), 1.0);
  EXPECT_EQ(off["crossing_success"].max(), 0.0);
}

// Paper 1's Fig. 6 as it judges it (issue 36 item 5): only the modified
// system crosses successfully, with the robots localizing themselves
// (localization.source fused, as scenarios/nominal_vs_modified.yaml).
// Expected: the nominal system leaves the 4 cm band in every run (its
// standing error v / k = 0.10 m, and its odometry, which takes the belt for
// a still floor, adds to it) although it reaches the far side; the modified
// one stays within it (as above, plus the localization's error, about 1
// cm). 20 runs (docs/results.md): nominal 107.8 / 114.2 / 121.0 mm,
// modified 4.9 / 5.8 / 6.2 mm; success 0 and 20 of 20. Seeds 1..4 here:
// nominal 106.1 / 108.4 / 115.6 mm, modified 5.0 / 5.4 / 5.6 mm.
TEST(Paper1Scenarios, Fig6OnlyTheModifiedSystemCrossesWithItsOwnLocalization) {
  const auto nominal = test_scenarios::RunSeeds(
      test_scenarios::Shipped("cross_line"),
      {"control.compensation=false", "sensing.surface_velocity=none", "localization.source=fused"},
      4);
  const auto modified = test_scenarios::RunSeeds(
      test_scenarios::Shipped("cross_line"),
      {"control.compensation=true", "sensing.surface_velocity=ground_truth",
       "localization.source=fused"},
      4);
  EXPECT_EQ(nominal["crossing_success"].max(), 0.0);
  EXPECT_GT(nominal["max_path_deviation_m"].min(), 0.5 * 0.10 / kGain);
  EXPECT_GT(nominal["final_progress_m"].min(), 3.9);
  EXPECT_EQ(modified["crossing_success"].min(), 1.0);
}

// The result is the system's, not an artefact of the coupling: it holds
// under the other master algorithm, at half and twice the step, and for a
// robot crossing at another heading (it is omnidirectional).
// max_path_deviation_m over seeds 1..8 (measured once; the test runs 1..2):
// jacobi 0.0049 / 0.0053 / 0.0059; step 0.5 ms 0.0050 / 0.0052 / 0.0057;
// step 2 ms 0.0049 / 0.0052 / 0.0057; yaw 0 deg 0.0076 at every seed (the
// start's transient, not the belt); yaw 45 deg 0.0022 at every seed.
// final_progress_m 3.9807..3.9810 in all.
TEST(Paper1Scenarios, CrossLineHoldsAcrossAlgorithmStepAndHeading) {
  // Two seeds per variant: the seed's effect is the belt's variation, which
  // CrossLineCompensatedStaysWithin4cmNominalDoesNot covers over 8 seeds;
  // each variant was measured over seeds 1..8 once (below) and its spread
  // is as narrow as the shipped case's.
  constexpr int kVariantSeeds = 2;
  for (const std::vector<std::string>& sets :
       std::vector<std::vector<std::string>>{{"master.algorithm=jacobi"},
                                             {"master.step_s=0.0005"},
                                             {"master.step_s=0.002"},
                                             {"robot.pose.yaw_deg=0"},
                                             {"robot.pose.yaw_deg=45"}}) {
    const auto on = RunScenario("cross_line", sets, kVariantSeeds);
    EXPECT_LT(on["max_path_deviation_m"].max(), 0.04) << sets.front();
    EXPECT_GT(on["final_progress_m"].min(), 3.9) << sets.front();
  }
}

// Paper 1, Sec. VI-C: position hold with the line at about 0.20 m/s
// switching on and off. Entirely on the belt, the nominal robot is carried
// until its position loop balances the belt: drift v/k = 0.20 m (+-10 %
// speed variation). With Algorithm 1 it stays put: we ask for a tenth of
// that at worst (the belt starts at 0.5 m/s2 faster than the 20 ms
// controller sees it) and a return to the point once the line runs
// steadily. The last switch is at 15 s, 9 s = 9/k before the end: of a
// transient within the 0.1 v/k bound, e^-9 of it (under 3 um) is left, plus
// the lag of the compensation behind the belt's speed variation (+-10 % of
// 0.20 m/s over 20 s: dv/dt <= 0.1 * 0.20 * 2 pi / 20 = 6.3 mm/s2, seen T =
// 20 ms late, held by k at 6.3e-3 * 0.02 / k = 0.13 mm). The final bound,
// 5 mm = 2.5 % of v/k, leaves room for the contact dynamics.
// Seeds 1..8: compensated max_position_drift_m 0.0075 / 0.0077 / 0.0081,
// final_position_drift_m 0.00001 / 0.00012 / 0.00019; nominal
// max_position_drift_m 0.2039 / 0.2053 / 0.2125 against [0.85, 1.15] v/k =
// [0.17, 0.23] (the upper end is the analytic limit 1.1 v/k, the belt's
// top speed over k, plus 5 % for the loop's lag: the nominal robot nears
// v/k by design, so its margin is 8 %, not 20).
TEST(Paper1Scenarios, HoldOnBeltHoldsWithCompensation) {
  const auto on = RunScenario("hold_on_belt", {"control.compensation=true"});
  const auto off = RunScenario("hold_on_belt", {"control.compensation=false"});
  const double v_over_k = 0.20 / kGain;
  EXPECT_LT(on["max_position_drift_m"].max(), 0.1 * v_over_k);
  EXPECT_LT(on["final_position_drift_m"].max(), 0.025 * v_over_k);  // 5 mm
  EXPECT_GT(off["max_position_drift_m"].min(), 0.85 * v_over_k);
  EXPECT_LT(off["max_position_drift_m"].max(), 1.15 * v_over_k);
}

// Straddling the edge only two wheels are dragged (the braked robot would
// yaw, see the chassis tests): the nominal robot both drifts, about half of
// v/k since half of the wheels push, and turns; the compensated one holds
// position and heading. Headings from the geometry: the belt-side and
// floor-side wheel rows are 0.32 m apart (models/robots/raw3.yaml y_m: 0.186
// + 0.134 m), so a displacement d of one row against the other turns the
// robot by d / 0.32 m. Compensated: the 5 mm final position bound (as on
// the belt) at one row alone would be 0.016 rad; we ask 0.01 rad. Nominal:
// the belt row is dragged by at least the asserted 0.3 v/k = 60 mm more
// than the robot's centre, so by twice that against the floor row if that
// row held still: 0.37 rad; the heading loop takes most of it back, and we
// ask for a seventh, 0.05 rad.
// Seeds 1..8: compensated max_position_drift_m 0.0037 / 0.0038 / 0.0040,
// final_position_drift_m 0.000002 / 0.00009 / 0.00017, |final_yaw_rad| under
// 4e-8; nominal max_position_drift_m 0.1040 / 0.1099 / 0.1167,
// final_yaw_rad 0.0987 / 0.1026 / 0.1044.
TEST(Paper1Scenarios, HoldStraddlingHoldsWithCompensation) {
  const auto on = RunScenario("hold_straddle", {"control.compensation=true"});
  const auto off = RunScenario("hold_straddle", {"control.compensation=false"});
  const double v_over_k = 0.20 / kGain;
  EXPECT_LT(on["max_position_drift_m"].max(), 0.1 * v_over_k);
  EXPECT_LT(on["final_position_drift_m"].max(), 0.025 * v_over_k);
  EXPECT_LT(on["final_yaw_rad"].max_abs(), 0.01);
  EXPECT_GT(off["max_position_drift_m"].min(), 0.3 * v_over_k);
  for (double yaw : off["final_yaw_rad"].values) EXPECT_GT(std::abs(yaw), 0.05);
}

// Records the period-2 part of every wheel's drive rate,
// |w[k+1] - 2 w[k] + w[k-1]| / 4, at every base step.
class StepChatter : public cosim::Observer {
 public:
  void OnStart(const cosim::Master& master) override {
    probes_ = cosim::ResolveProbes(master.system(), {"chassis.drive_rate"});
    last_.assign(probes_.size(), {});
    samples_ = 0;
  }
  void OnSample(cosim::TimeNs, const cosim::System& system) override {
    ++samples_;
    for (std::size_t w = 0; w < probes_.size(); ++w) {
      // The last three samples, newest first.
      auto& h = last_[w];
      h = {cosim::ReadProbe(system, probes_[w]), h[0], h[1]};
      max_rate_ = std::max(max_rate_, std::abs(h[0]));
      if (samples_ >= 3) {
        const double a = std::abs(h[0] - 2.0 * h[1] + h[2]) / 4;
        sum_sq_ += a * a;
        ++count_;
      }
    }
  }
  double rms() const { return std::sqrt(sum_sq_ / static_cast<double>(count_)); }
  double max_rate() const { return max_rate_; }

 private:
  std::vector<cosim::Probe> probes_;
  std::vector<std::array<double, 3>> last_;
  std::size_t samples_ = 0;
  double sum_sq_ = 0, max_rate_ = 0;
  std::size_t count_ = 0;
};

// Guards against a numerical limit cycle between the wheels and the floor
// (a sliding contact's slip direction swinging each step made the wheel
// rates alternate by 8 % every 1 ms when the nominal robot fights the belt
// at its edge). A wheel's rate is a mechanical signal: its fastest time
// constant is the bare wheel's J / b = 0.022 kg.m2 / 1.01 N.m.s/rad = 22 ms
// (chassis model and motor back-EMF at the wheel), so over h = 1 ms its
// second difference is of order (h / tau)^2 = 0.2 % of the rate; a step
// chatter is far above that. Seeds 1..8: rms / max rate 0.00083 / 0.00093
// / 0.00098 against 0.002.
TEST(Paper1Scenarios, WheelRatesHaveNoStepChatterWhenFightingTheBelt) {
  std::vector<double> ratio;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    loader::Scenario s = loader::LoadScenario(
        std::string(LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml"),
        {"control.compensation=false", kNoSensors, "seed=" + std::to_string(seed)});
    StepChatter chatter;
    s.master->AddObserver(&chatter);
    ASSERT_TRUE(s.master->Run().ok);
    std::cout << "seed " << seed << ": period-2 drive-rate amplitude: rms " << chatter.rms()
              << " rad/s, max rate " << chatter.max_rate() << " rad/s\n";
    ratio.push_back(chatter.rms() / chatter.max_rate());
  }
  const auto r = test_spread::Print("chatter rms / max rate", ratio);
  EXPECT_LT(r.max(), 0.002);
}

}  // namespace
}  // namespace linesim
