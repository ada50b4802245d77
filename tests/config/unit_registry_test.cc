#include "config/unit_registry.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace linesim::config {
namespace {

// Registered in the reverse of their names' order: the registry sorts.
const UnitTypeRegistrar kZeta({"zeta_probe", "the last one", "", {}, nullptr});
const UnitTypeRegistrar kAlpha(
    {"alpha_probe", "the first one", "", {{"count", "how many"}}, nullptr});

// Guards `inspect` and the known-types lists: the order is the names'
// order, whatever order the registrars ran in.
TEST(UnitRegistry, TypesAreSortedByName) {
  EXPECT_EQ(UnitTypeNames(), (std::vector<std::string>{"alpha_probe", "zeta_probe"}));
  ASSERT_NE(FindUnitType("alpha_probe"), nullptr);
  EXPECT_EQ(FindUnitType("alpha_probe")->description, "the first one");
  ASSERT_EQ(FindUnitType("alpha_probe")->structural_keys.size(), 1u);
  EXPECT_EQ(FindUnitType("alpha_probe")->structural_keys[0].name, "count");
  EXPECT_EQ(FindUnitType("alpha"), nullptr);
}

TEST(UnitRegistry, UnknownTypeNamesTheClosestAndEveryKnownType) {
  EXPECT_EQ(UnknownTypeMessage("zeta_prob"),
            "unknown unit type 'zeta_prob' (closest: zeta_probe); known types: alpha_probe, "
            "zeta_probe");
}

TEST(UnitRegistryDeathTest, ANameRegisteredTwiceAborts) {
  EXPECT_DEATH(RegisterUnitType({"zeta_probe", "again", "", {}, nullptr}),
               "unit type 'zeta_probe' is registered twice");
}

}  // namespace
}  // namespace linesim::config
