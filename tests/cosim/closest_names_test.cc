// "Did you mean" suggestions for unknown names.

#include "cosim/closest_names.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace linesim::cosim {
namespace {

// Guards against: a wrong edit distance. Textbook values: kitten -> sitting
// is 3 (two substitutions, one insertion); to or from the empty string it is
// the length; equal strings 0.
TEST(EditDistance, TextbookValues) {
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(EditDistance("flaw", "lawn"), 2u);
  EXPECT_EQ(EditDistance("", "abc"), 3u);
  EXPECT_EQ(EditDistance("abc", ""), 3u);
  EXPECT_EQ(EditDistance("speed", "speed"), 0u);
  EXPECT_EQ(EditDistance("robto", "robot"), 2u);
}

// Guards against: suggestions in the wrong order or unrelated names offered.
TEST(ClosestNames, BestFirstAndOnlyPlausible) {
  const std::vector<std::string> units = {"chassis", "motor_left", "motor_right", "belt"};
  EXPECT_EQ(ClosestNames("chasis", units), (std::vector<std::string>{"chassis"}));
  EXPECT_EQ(ClosestNames("motor_lft", units),
            (std::vector<std::string>{"motor_left", "motor_right"}));
  EXPECT_TRUE(ClosestNames("xyz", units).empty());
  EXPECT_TRUE(ClosestNames("anything", {}).empty());
}

// Guards against: missing the obvious when a name is a part of the real one
// ("left" for "motor_left"), which plain edit distance ranks far away.
TEST(ClosestNames, ContainmentCountsAsClose) {
  const std::vector<std::string> names = {"wheel_speed_left", "wheel_speed_right", "yaw"};
  EXPECT_EQ(ClosestNames("speed_left", names).front(), "wheel_speed_left");
  EXPECT_EQ(ClosestNames("right", names), (std::vector<std::string>{"wheel_speed_right"}));
}

// Guards against: long messages listing every candidate, or repeats.
TEST(ClosestNames, AtMostMaxCountWithoutDuplicates) {
  const std::vector<std::string> names = {"v1", "v2", "v3", "v4", "v1"};
  EXPECT_EQ(ClosestNames("v", names).size(), 3u);
  EXPECT_EQ(ClosestNames("v", names, 10), (std::vector<std::string>{"v1", "v2", "v3", "v4"}));
}

// Guards against: a malformed hint in error messages.
TEST(ClosestHint, FormatsOrIsEmpty) {
  EXPECT_EQ(ClosestHint("mas1", {"mass1", "coupling"}), " (closest: mass1)");
  EXPECT_EQ(ClosestHint("speed", {"speed_x", "speed_y"}), " (closest: speed_x, speed_y)");
  EXPECT_EQ(ClosestHint("zzz", {"mass1", "coupling"}), "");
}

}  // namespace
}  // namespace linesim::cosim
