// The distance between robots' bodies in a fleet, and their contacts.
#include "units/evaluation/robot_clearance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "tests/units/test_helpers.h"

namespace linesim::evaluation {
namespace {

using test_helpers::Get;
using test_helpers::SetArray;

constexpr cosim::TimeNs kStep = 5'000'000;

std::vector<double> Box(double x, double y, double yaw, double length, double width) {
  return {x, y, yaw, 0.0, 0.0, 0.0, length, width, 0.0, 0.4};
}

// Guards the footprint distance against its closed forms: two axis-aligned
// 1 x 1 boxes 2 m apart are 1 m apart; one turned by 45 deg (a diamond,
// half diagonal sqrt(0.5)) at 2 m is 2 - 0.5 - sqrt(0.5) from the other's
// face; side by side 1.2 m apart diagonally (0.2 m along x and y) their
// corners are sqrt(0.2^2 + 0.2^2) apart; overlapping boxes are at 0; the
// distance is symmetric.
TEST(RobotClearance, FootprintDistanceClosedForms) {
  const auto d = [](const std::vector<double>& a, const std::vector<double>& b) {
    EXPECT_DOUBLE_EQ(RobotClearanceUnit::FootprintDistance(a.data(), b.data()),
                     RobotClearanceUnit::FootprintDistance(b.data(), a.data()));
    return RobotClearanceUnit::FootprintDistance(a.data(), b.data());
  };
  const double quarter = std::numbers::pi / 4.0;
  EXPECT_NEAR(d(Box(0, 0, 0, 1, 1), Box(2, 0, 0, 1, 1)), 1.0, 1e-12);
  EXPECT_NEAR(d(Box(0, 0, 0, 1, 1), Box(2, 0, quarter, 1, 1)), 1.5 - std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(d(Box(0, 0, 0, 1, 1), Box(1.2, 1.2, 0, 1, 1)), std::hypot(0.2, 0.2), 1e-12);
  EXPECT_EQ(d(Box(0, 0, 0, 1, 1), Box(0.9, 0.3, 0.4, 1, 1)), 0.0);
  // A long box across a short one's end (a T): the gap along x.
  EXPECT_NEAR(d(Box(0, 0, 0, 1, 0.5), Box(1.0, 0, std::numbers::pi / 2, 2, 0.2)), 0.4, 1e-12);
}

// Guards the nearest-corner search (squared distances first, then the
// hypot of the corners that can tie at rounding): for separated boxes the
// distance is exactly the least of the eight corner distances, each the
// hypot of how far the corner lies outside the other box along its axes
// (what it computed before the search). 2000 random pairs, a fixed seed.
TEST(RobotClearance, FootprintDistanceIsTheLeastCornerHypotToTheBit) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(-4.0, 4.0), yaw(-3.2, 3.2), size(0.2, 1.5);
  const auto outside = [](const std::vector<double>& box, double px, double py) {
    const double c = std::cos(box[2]), s = std::sin(box[2]);
    const double dx = px - box[0], dy = py - box[1];
    const double ex = std::abs(c * dx + s * dy) - 0.5 * box[6];
    const double ey = std::abs(-s * dx + c * dy) - 0.5 * box[7];
    return std::hypot(std::max(ex, 0.0), std::max(ey, 0.0));
  };
  const auto corners = [](const std::vector<double>& box) {
    const double c = std::cos(box[2]), s = std::sin(box[2]);
    std::vector<std::array<double, 2>> out;
    for (const auto& [sx, sy] : {std::pair{1, 1}, {-1, 1}, {-1, -1}, {1, -1}}) {
      const double px = sx * 0.5 * box[6], py = sy * 0.5 * box[7];
      out.push_back({box[0] + c * px - s * py, box[1] + s * px + c * py});
    }
    return out;
  };
  int separated = 0;
  for (int i = 0; i < 2000; ++i) {
    const auto a = Box(pos(rng), pos(rng), yaw(rng), size(rng), size(rng));
    const auto b = Box(pos(rng), pos(rng), yaw(rng), size(rng), size(rng));
    const double d = RobotClearanceUnit::FootprintDistance(a.data(), b.data());
    if (d == 0.0) continue;  // overlapping
    ++separated;
    double least = std::numeric_limits<double>::max();
    for (const auto& p : corners(a)) least = std::min(least, outside(b, p[0], p[1]));
    for (const auto& p : corners(b)) least = std::min(least, outside(a, p[0], p[1]));
    ASSERT_EQ(d, least) << "pair " << i;
  }
  EXPECT_GT(separated, 1500);  // most random pairs in 8 x 8 m are apart
}

// Guards the contact events: a collision is counted when the bodies come
// within contact_distance (default 5 mm) and not again while they stay;
// leaving and touching again counts again; a body above the other (no
// height in common) is never in contact; an absent one (length 0) is
// ignored.
TEST(RobotClearance, CountsContactEventsPerPair) {
  // Three robots: this one is body 1; body 0 comes and goes, body 2 is
  // absent.
  RobotClearanceUnit u("c", 3);
  u.variables().SetInteger(*u.variables().Find("own"), 1);
  u.Initialize();
  cosim::TimeNs t = 0;
  const auto step = [&](double x_other, double z_bottom) {
    std::vector<double> bodies = Box(x_other, 0, 0, 1, 1);
    bodies[8] = z_bottom;
    bodies[9] = z_bottom + 0.4;
    for (const auto& b : {Box(0, 0, 0, 1, 1), Box(0, 0, 0, 0, 0)}) {
      bodies.insert(bodies.end(), b.begin(), b.end());
    }
    SetArray(u, "bodies", bodies);
    ASSERT_EQ(u.DoStep(t, kStep), cosim::StepResult::kOk) << u.last_error();
    t += kStep;
  };
  step(2.0, 0.0);
  EXPECT_NEAR(Get(u, "distance")[0], 1.0, 1e-12);
  EXPECT_EQ(Get(u, "nearest")[0], 0.0);
  EXPECT_EQ(Get(u, "robot_distance")[1], -1.0);  // its own
  EXPECT_EQ(Get(u, "collisions")[0], 0.0);
  step(1.003, 0.0);  // 3 mm: in contact
  step(1.0, 0.0);    // still
  EXPECT_EQ(Get(u, "collisions")[0], 1.0);
  step(1.1, 0.0);  // apart
  step(0.9, 0.0);  // overlapping: again
  EXPECT_EQ(Get(u, "robot_collisions")[0], 2.0);
  EXPECT_EQ(Get(u, "robot_collisions")[1], 0.0);
  EXPECT_EQ(Get(u, "robot_collisions")[2], 0.0);
  step(0.9, 0.5);  // above it
  step(0.9, 0.0);
  EXPECT_EQ(Get(u, "collisions")[0], 3.0);
  EXPECT_EQ(Get(u, "min_distance")[0], 0.0);
}

}  // namespace
}  // namespace linesim::evaluation
