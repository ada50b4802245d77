#include "config/yaml_reader.h"

#include <gtest/gtest.h>

namespace linesim::config {
namespace {

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Guards times: whole nanoseconds, a nonzero time below 1 ns and one beyond
// cosim::kMaxTimeSeconds (4.6e9 s: half of int64 nanoseconds, so that a time
// plus a duration fits; 5e9 s would fit on its own) refused at their keys
// instead of silently becoming 0 (or one master step) or throwing.
TEST(YamlReader, TimeIsWholeNanosecondsAndRefusesWhatTheyCannotHold) {
  const YAML::Node map = YAML::Load("{ok: 0.002, zero: 0, tiny: 1.0e-10, huge: 5.0e9, nan: .nan}");
  YamlReader r("f.yaml");
  EXPECT_EQ(r.Time(map, "m", "ok", std::nullopt), 2'000'000);
  EXPECT_EQ(r.Time(map, "m", "zero", std::nullopt), 0);
  EXPECT_EQ(r.Time(map, "m", "absent", 0.5), 500'000'000);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.Time(map, "m", "tiny", 0.001), 1'000'000);  // refused: the fallback
  EXPECT_EQ(r.Time(map, "m", "huge", std::nullopt), 0);
  EXPECT_EQ(r.Time(map, "m", "nan", std::nullopt), 0);
  EXPECT_EQ(r.Time(map, "m", "tiny", std::nullopt, {0.0, 1.0, true}), 0);
  ASSERT_EQ(r.issues().size(), 4u);
  EXPECT_EQ(r.issues()[0].key_path, "m.tiny");
  EXPECT_TRUE(Has(r.issues()[0].message, "below one nanosecond")) << r.issues()[0].message;
  EXPECT_TRUE(Has(r.issues()[0].message, "expected 0 or at least 1e-9 s")) << r.issues()[0].message;
  EXPECT_EQ(r.issues()[1].key_path, "m.huge");
  EXPECT_TRUE(Has(r.issues()[1].message, "within +-4.6e9 s")) << r.issues()[1].message;
  EXPECT_TRUE(Has(r.issues()[1].message, "int64 nanoseconds")) << r.issues()[1].message;
  EXPECT_EQ(r.issues()[2].key_path, "m.nan");
  EXPECT_TRUE(Has(r.issues()[2].message, "expected a number")) << r.issues()[2].message;
  // Where 0 is out of range, the message does not offer it.
  EXPECT_TRUE(Has(r.issues()[3].message, "expected at least 1e-9 s")) << r.issues()[3].message;
  EXPECT_FALSE(Has(r.issues()[3].message, "0 or")) << r.issues()[3].message;
}

// Guards issue 24: `--set key=` leaves null in the tree, which every typed
// reader took as absent, so the key silently got its default (ground truth
// for sensing.surface_velocity) with exit 0. A key given without a value is
// refused, naming the key and what it takes (the allowed values); the same
// null written in the file, or an absent key, still means the default.
TEST(YamlReader, KeyGivenWithoutValueOnTheCommandLineIsRefused) {
  const YAML::Node map = YAML::Load("{s: ~, r: ~, t: ~, i: ~, b: ~, written: ~}");
  YamlReader r("f.yaml", {"m.s", "m.r", "m.t", "m.i", "m.b"});
  r.SetGivenWithoutValue({"m.s", "m.r", "m.t", "m.i", "m.b"});
  EXPECT_EQ(r.String(map, "m", "s", "ground_truth", {"ground_truth", "px4flow"}), "ground_truth");
  r.Real(map, "m", "r", 1.0, {0.0, 2.0, true});
  r.Time(map, "m", "t", 0.5);
  r.Integer(map, "m", "i", 3, 1, 9);
  r.Boolean(map, "m", "b", true);
  EXPECT_EQ(r.String(map, "m", "written", "x"), "x");
  EXPECT_EQ(r.Real(map, "m", "absent", 2.0), 2.0);
  ASSERT_EQ(r.issues().size(), 5u);
  const auto& s = r.issues()[0];
  EXPECT_EQ(s.key_path, "m.s");
  EXPECT_TRUE(s.from_command_line);
  EXPECT_TRUE(Has(s.message, "no value given (--set m.s=): expected one of ground_truth, px4flow; "
                             "to keep the default, leave the --set out"))
      << s.message;
  EXPECT_TRUE(Has(r.issues()[1].message, "expected a number > 0 and <= 2")) << r.issues()[1].message;
  EXPECT_TRUE(Has(r.issues()[2].message, "expected a time in seconds")) << r.issues()[2].message;
  EXPECT_TRUE(Has(r.issues()[3].message, "expected an integer from 1 to 9")) << r.issues()[3].message;
  EXPECT_TRUE(Has(r.issues()[4].message, "expected true or false")) << r.issues()[4].message;
  // A required key has no default to offer.
  YamlReader q("f.yaml", {"m.s"});
  q.SetGivenWithoutValue({"m.s"});
  q.String(map, "m", "s", std::nullopt);
  ASSERT_EQ(q.issues().size(), 1u);
  EXPECT_TRUE(Has(q.issues()[0].message, "no value given (--set m.s=): expected a text"));
  EXPECT_FALSE(Has(q.issues()[0].message, "default")) << q.issues()[0].message;
}

}  // namespace
}  // namespace linesim::config
