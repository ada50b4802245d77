#include "loader/overrides.h"

#include <gtest/gtest.h>

namespace linesim::loader {
namespace {

// Guards value typing: YAML scalars keep their types and lists stay lists.
TEST(ApplyOverrides, WritesTypedValuesIntoTheTree) {
  YAML::Node root = YAML::Load("a: {b: 1, c: [1, 2, 3]}\nflag: false\n");
  std::vector<Issue> issues;
  ApplyOverrides(root,
                 {ParseOverride("a.b=2.5"), ParseOverride("a.c.2=7"), ParseOverride("flag=true"),
                  ParseOverride("a.d=[4, 5]")},
                 "f.yaml", issues);
  EXPECT_TRUE(issues.empty());
  EXPECT_EQ(root["a"]["b"].as<double>(), 2.5);
  EXPECT_EQ(root["a"]["c"][2].as<int>(), 7);
  EXPECT_TRUE(root["flag"].as<bool>());
  EXPECT_EQ(root["a"]["d"].size(), 2u);
}

// Guards against creating whole subtrees from a typo: only the last key may
// be new, and an unknown intermediate key names the closest one.
TEST(ApplyOverrides, UnknownIntermediateKeyIsAnIssue) {
  YAML::Node root = YAML::Load("master: {step_s: 0.001}\n");
  std::vector<Issue> issues;
  ApplyOverrides(root, {ParseOverride("mastr.step_s=1"), ParseOverride("master.step_s.x=1")},
                 "f.yaml", issues);
  ASSERT_EQ(issues.size(), 2u);
  EXPECT_NE(issues[0].message.find("closest: master"), std::string::npos) << issues[0].message;
  EXPECT_TRUE(issues[0].from_command_line);
  EXPECT_NE(issues[1].message.find("holds a value"), std::string::npos) << issues[1].message;
  EXPECT_FALSE(root["mastr"].IsDefined());
}

// Guards the message for a list item of a value the file does not write
// (e.g. a parameter left to its model file): it says how to set it.
TEST(ApplyOverrides, ItemOfAnAbsentListSaysToSetTheWholeValue) {
  YAML::Node root = YAML::Load("units: {m: {parameters: {count: 2}}}\n");
  std::vector<Issue> issues;
  ApplyOverrides(root, {ParseOverride("units.m.parameters.resistance.1=0.5")}, "f.yaml", issues);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_NE(issues[0].message.find("set the whole value instead, e.g. "
                                   "units.m.parameters.resistance=[...]"),
            std::string::npos)
      << issues[0].message;
}

// Guards against an index too large for any integer type aborting the
// program: it is reported like any index past the end of the list.
TEST(ApplyOverrides, HugeListIndexIsNotAnItem) {
  YAML::Node root = YAML::Load("line: {belts: [{speed_mps: 0.1}]}\n");
  std::vector<Issue> issues;
  ApplyOverrides(root, {ParseOverride("line.belts.99999999999999999999999=1")}, "f.yaml", issues);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_NE(issues[0].message.find("'line.belts.99999999999999999999999' is not an item of the "
                                   "list at 'line.belts', which has 1 items"),
            std::string::npos)
      << issues[0].message;
}

// Guards against a list, map or quoted string with a typo being taken as a
// plain string (and refused later with a confusing message): it is reported
// at its key with the parser's message, and the tree is left alone. Plain
// text that YAML refuses is still a string.
TEST(ApplyOverrides, UnparsableStructuredValueIsAnIssue) {
  YAML::Node root = YAML::Load("a: {b: 1}\n");
  std::vector<Issue> issues;
  ApplyOverrides(root,
                 {ParseOverride("a.b=[1, 2"), ParseOverride("a.c= {x: 1"),
                  ParseOverride("a.d=\"open"), ParseOverride("a.e=x: y: z")},
                 "f.yaml", issues);
  ASSERT_EQ(issues.size(), 3u);
  EXPECT_EQ(issues[0].key_path, "a.b");
  EXPECT_EQ(issues[0].message.rfind("value is not valid YAML: ", 0), 0u) << issues[0].message;
  EXPECT_NE(issues[0].message.find("(in --set a.b=[1, 2)"), std::string::npos) << issues[0].message;
  EXPECT_TRUE(issues[0].from_command_line);
  EXPECT_FALSE(issues[0].unknown_path);
  EXPECT_EQ(issues[1].key_path, "a.c");
  EXPECT_EQ(issues[2].key_path, "a.d");
  EXPECT_EQ(root["a"]["b"].as<int>(), 1);
  EXPECT_FALSE(root["a"]["c"].IsDefined());
  EXPECT_EQ(root["a"]["e"].as<std::string>(), "x: y: z");
}

}  // namespace
}  // namespace linesim::loader
