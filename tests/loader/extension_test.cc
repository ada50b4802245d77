// A provider and a robot added from a test folder alone: the provider is
// registered here (as a file of loader/assembly/providers/ registers
// itself), the robot is tests/loader/extension/cart.yaml, and a fleet
// scenario there uses both; no file of the loader or the models changes.
#include <gtest/gtest.h>

#include <string>

#include "cosim/observers.h"
#include "loader/assembly/providers.h"
#include "tests/loader/scenario_test.h"

namespace linesim::loader {
namespace {

int g_provider_calls = 0;

// The truth, through a provider of the test's own: the chassis' outputs.
void TestTruth(assembly::SystemBuilder&, const assembly::ProviderContext&, assembly::Signals& s) {
  ++g_provider_calls;
  s.position = s.true_position;
  s.yaw = s.true_yaw;
  s.velocity = assembly::Signal(assembly::kChassis, "linear_velocity");
  s.yaw_rate = assembly::Signal(assembly::kChassis, "yaw_rate");
}

const assembly::ProviderRegistrar kTestTruth(assembly::ProviderRole::kLocalization,
                                             "test_truth_by_provider", TestTruth);

const std::string kFleet = LINESIM_SOURCE_DIR "/tests/loader/extension/fleet_with_cart.yaml";

// Guards the open registries: the test's provider is chosen by name and
// built into the cart's units, the cart is built from the test folder's
// file (its body is the chassis'), and the fleet runs, the cart finishing
// its 2 m path; a scenario naming an unknown provider is told the test's
// among the registered ones.
TEST(Extension, ProviderAndRobotFromATestFolder) {
  g_provider_calls = 0;
  Scenario s = LoadScenario(kFleet);
  EXPECT_EQ(g_provider_calls, 1);  // the cart's, not the raw3's
  EXPECT_EQ(testing::Param(s, "cart.chassis", "body_length"), 0.6);
  EXPECT_EQ(testing::Param(s, "cart.chassis", "wheel_radius", 0), 0.1);
  cosim::MetricsObserver metrics(s.metrics);
  s.master->AddObserver(&metrics);
  const auto result = s.master->Run();
  ASSERT_TRUE(result.ok) << result.ErrorText();
  const auto m = metrics.Results();
  const auto get = [&](const std::string& name) {
    for (const auto& [k, v] : m) {
      if (k == name) return v;
    }
    ADD_FAILURE() << "no metric " << name;
    return 0.0;
  };
  EXPECT_GT(get("cart.final_progress_m"), 1.9);
  EXPECT_EQ(get("cart.robot_collisions"), 0.0);

  const std::string issues = testing::Issues(kFleet, {"robots.1.localization.source=nope"});
  EXPECT_TRUE(testing::Has(issues, "robots.1.localization.source")) << issues;
  EXPECT_TRUE(testing::Has(issues, "test_truth_by_provider")) << issues;
}

}  // namespace
}  // namespace linesim::loader
