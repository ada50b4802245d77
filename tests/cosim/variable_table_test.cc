// VariableTable: declaration, start values, typed and generic access, and
// the checks that keep a unit's declaration consistent.

#include "cosim/variable_table.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace linesim::cosim {
namespace {

using ::testing::HasSubstr;

// A unit-like holder: members declared once, in the constructor.
struct Holder {
  Holder() {
    gain_ref = t.Parameter("gain", "1", &gain, "a real parameter");
    offsets_ref = t.Parameter("offsets", "m", &offsets, "an array parameter");
    mode_ref = t.Parameter("mode", &mode, "an integer parameter");
    enabled_ref = t.Parameter("enabled", &enabled, "a boolean parameter");
    frame_ref = t.Parameter("frame", &frame, "a string parameter");
    speed_ref = t.Input("speed", "m/s", &speed, "a real input");
    scan_ref = t.Input("scan", "m", &scan, "an array input");
    count_ref = t.Input("count", &count, "an integer input");
    on_ref = t.Input("on", &on, "a boolean input");
    force_ref = t.Output("force", "N", &force, "depends on speed and on", {"speed", "on"});
    state_ref = t.Local("state", "m", &state, "a local");
  }
  VariableTable t;
  double gain = 2.5;
  std::vector<double> offsets = {0.1, -0.2};
  std::int64_t mode = 3;
  bool enabled = true;
  std::string frame = "odom";
  double speed = -1.25;
  std::vector<double> scan = {1.0, 2.0, 3.0};
  std::int64_t count = 0;
  bool on = false;
  double force = 0.0;
  double state = 7.0;
  ValueRef gain_ref, offsets_ref, mode_ref, enabled_ref, frame_ref, speed_ref, scan_ref, count_ref,
      on_ref, force_ref, state_ref;
};

// Guards against: start values not taken from the bound members at
// declaration, refs not being table indices, or wrong declared metadata.
TEST(VariableTable, DeclarationRecordsStartValuesAndMetadata) {
  Holder h;
  EXPECT_EQ(h.t.size(), 11u);
  EXPECT_EQ(h.gain_ref, 0u);
  EXPECT_EQ(h.state_ref, 10u);
  EXPECT_EQ(std::get<double>(h.t.info(h.gain_ref).start), 2.5);
  EXPECT_EQ(std::get<std::vector<double>>(h.t.info(h.offsets_ref).start),
            (std::vector<double>{0.1, -0.2}));
  EXPECT_EQ(std::get<std::int64_t>(h.t.info(h.mode_ref).start), 3);
  EXPECT_EQ(std::get<bool>(h.t.info(h.enabled_ref).start), true);
  EXPECT_EQ(std::get<std::string>(h.t.info(h.frame_ref).start), "odom");
  EXPECT_EQ(std::get<double>(h.t.info(h.speed_ref).start), -1.25);

  const VariableInfo& scan = h.t.info(h.scan_ref);
  EXPECT_EQ(scan.type, VarType::kRealArray);
  EXPECT_EQ(scan.size, 3u);
  EXPECT_EQ(scan.causality, Causality::kInput);
  EXPECT_EQ(scan.variability, Variability::kContinuous);
  EXPECT_EQ(scan.unit, "m");
  EXPECT_EQ(h.t.info(h.count_ref).variability, Variability::kDiscrete);
  EXPECT_EQ(h.t.info(h.count_ref).unit, "1");
  EXPECT_EQ(h.t.info(h.gain_ref).variability, Variability::kFixed);
  EXPECT_EQ(h.t.info(h.state_ref).causality, Causality::kLocal);
  EXPECT_EQ(h.t.info(h.force_ref).depends_on, (std::vector<ValueRef>{h.speed_ref, h.on_ref}));
  EXPECT_TRUE(h.t.info(h.speed_ref).depends_on.empty());

  EXPECT_EQ(h.t.Find("count"), h.count_ref);
  EXPECT_FALSE(h.t.Find("nothing").has_value());
  EXPECT_EQ(h.t.Names().front(), "gain");
  EXPECT_EQ(h.t.Names().back(), "state");
}

// Guards against: the table copying values instead of binding members: a
// Set must be visible in the member and a member change in Get.
TEST(VariableTable, AccessorsReadAndWriteTheBoundMembers) {
  Holder h;
  h.t.SetReal(h.speed_ref, 4.0);
  EXPECT_EQ(h.speed, 4.0);
  h.state = -3.0;
  EXPECT_EQ(h.t.GetReal(h.state_ref), -3.0);
  h.t.SetRealElement(h.scan_ref, 2, 9.0);
  EXPECT_EQ(h.scan[2], 9.0);
  EXPECT_EQ(h.t.GetRealElement(h.scan_ref, 0), 1.0);
  EXPECT_THROW(h.t.GetRealElement(h.scan_ref, 3), std::out_of_range);
  const std::vector<double> new_scan = {4.0, 5.0, 6.0};
  h.t.SetRealArray(h.scan_ref, new_scan);
  EXPECT_EQ(h.scan, new_scan);
  h.t.SetInteger(h.count_ref, 12);
  EXPECT_EQ(h.count, 12);
  h.t.SetBoolean(h.on_ref, true);
  EXPECT_TRUE(h.on);
  h.t.SetString(h.frame_ref, "map");
  EXPECT_EQ(h.frame, "map");
}

// Guards against: typed access that silently reinterprets memory (a bool
// read as a double is garbage) or writes past an array.
TEST(VariableTable, TypedAccessChecksTypeAndSize) {
  Holder h;
  try {
    h.t.GetInteger(h.speed_ref);
    FAIL();
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "variable 'speed' is Real, accessed as Integer");
  }
  EXPECT_THROW(h.t.GetReal(h.scan_ref), std::logic_error);
  EXPECT_THROW(h.t.SetBoolean(h.count_ref, true), std::logic_error);
  EXPECT_THROW(h.t.GetReal(999), std::logic_error);
  const std::vector<double> two = {1.0, 2.0};
  try {
    h.t.SetRealArray(h.scan_ref, two);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "'scan' holds 3 elements, got 2");
  }
}

// Guards against: boundary values of the wrong kind being accepted or
// mangled. Documented conversions: an integer to a real, a scalar (real or
// integer) to every element of an array; everything else is refused saying
// what was expected.
TEST(VariableTable, SetValueConvertsAndRefuses) {
  Holder h;
  h.t.SetValue(h.gain_ref, std::int64_t{4});
  EXPECT_EQ(h.gain, 4.0);
  h.t.SetValue(h.scan_ref, 0.5);
  EXPECT_EQ(h.scan, (std::vector<double>{0.5, 0.5, 0.5}));
  h.t.SetValue(h.scan_ref, std::int64_t{2});
  EXPECT_EQ(h.scan, (std::vector<double>{2.0, 2.0, 2.0}));
  h.t.SetValue(h.scan_ref, std::vector<double>{7.0, 8.0, 9.0});
  EXPECT_EQ(h.scan, (std::vector<double>{7.0, 8.0, 9.0}));
  h.t.SetValue(h.mode_ref, std::int64_t{-1});
  EXPECT_EQ(h.mode, -1);

  const auto message = [&](ValueRef ref, const Value& v) -> std::string {
    try {
      h.t.SetValue(ref, v);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(message(h.gain_ref, true), "expected a number, got true");
  EXPECT_EQ(message(h.gain_ref, std::string("fast")), "expected a number, got \"fast\"");
  EXPECT_EQ(message(h.mode_ref, 1.5), "expected an integer, got 1.5");
  EXPECT_EQ(message(h.enabled_ref, std::int64_t{1}), "expected true or false, got 1");
  EXPECT_EQ(message(h.frame_ref, 2.0), "expected a string, got 2");
  EXPECT_EQ(message(h.scan_ref, std::vector<double>{1.0, 2.0}),
            "expected a number or a list of 3 numbers, got a list of 2");
  EXPECT_EQ(message(h.scan_ref, false), "expected a number or a list of 3 numbers, got false");
  EXPECT_EQ(h.mode, -1);  // refused values leave the member alone
}

// Guards against: GetValue returning the wrong alternative of the variant
// (which would break SaveState and the recorder).
TEST(VariableTable, GetValueReturnsTheDeclaredType) {
  Holder h;
  EXPECT_EQ(h.t.GetValue(h.gain_ref), Value(2.5));
  EXPECT_EQ(h.t.GetValue(h.mode_ref), Value(std::int64_t{3}));
  EXPECT_EQ(h.t.GetValue(h.enabled_ref), Value(true));
  EXPECT_EQ(h.t.GetValue(h.frame_ref), Value(std::string("odom")));
  EXPECT_EQ(h.t.GetValue(h.scan_ref), Value(std::vector<double>{1.0, 2.0, 3.0}));
}

// Guards against: two variables with one name (lookups would find only one
// of them) and nameless variables.
TEST(VariableTable, RefusesDuplicateAndEmptyNames) {
  VariableTable t;
  double a = 0, b = 0;
  t.Input("x", "m", &a, "first");
  try {
    t.Output("x", "m", &b, "second", {});
    FAIL();
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "variable 'x' declared twice");
  }
  EXPECT_THROW(t.Local("", "m", &b, "nameless"), std::logic_error);
  EXPECT_EQ(t.size(), 1u);
}

// Guards against: feedthrough declared on something that is not an input
// declared before the output, which would corrupt the algebraic-loop check.
TEST(VariableTable, DependsOnMustNameAnEarlierInput) {
  VariableTable t;
  double u = 0, p = 0, y = 0, z = 0, w = 0, late = 0;
  t.Parameter("p", "1", &p, "a parameter");
  t.Input("u", "1", &u, "an input");
  t.Output("y", "1", &y, "ok", {"u"});
  try {
    t.Output("z", "1", &z, "depends on an unknown name", {"nope"});
    FAIL();
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(),
                 "output 'z' depends on 'nope', which is not an input declared before it");
  }
  EXPECT_THROW(t.Output("z", "1", &z, "depends on a parameter", {"p"}), std::logic_error);
  EXPECT_THROW(t.Output("z", "1", &z, "depends on an output", {"y"}), std::logic_error);
  EXPECT_THROW(t.Output("w", "1", &w, "depends on a later input", {"late"}), std::logic_error);
  t.Input("late", "1", &late, "declared after w was refused");
  EXPECT_EQ(t.size(), 4u);  // p, u, y, late: refused outputs were not added
}

// Guards against: the finite checks scanning parameters, locals or
// non-real signals, or naming the wrong element of an array.
TEST(VariableTable, FirstNonFiniteScansTheListedRealSignals) {
  Holder h;
  EXPECT_EQ(h.t.real_inputs(), (std::vector<ValueRef>{h.speed_ref, h.scan_ref}));
  EXPECT_EQ(h.t.real_outputs(), (std::vector<ValueRef>{h.force_ref}));
  EXPECT_EQ(FirstNonFinite(h.t, h.t.real_inputs()), std::nullopt);
  h.gain = std::numeric_limits<double>::quiet_NaN();  // a parameter: not scanned
  h.state = std::numeric_limits<double>::infinity();  // a local: not scanned
  EXPECT_EQ(FirstNonFinite(h.t, h.t.real_inputs()), std::nullopt);
  h.scan[2] = -std::numeric_limits<double>::infinity();
  EXPECT_EQ(FirstNonFinite(h.t, h.t.real_inputs()), "input 'scan[2]' is -inf");
  h.force = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(FirstNonFinite(h.t, h.t.real_outputs()), "output 'force' is nan");
}

// Guards against: the one-pass checks (RealInputsFinite, RealOutputsFinite:
// the master's every step) missing a value FindNonFinite finds, or scanning
// what it does not; and the resolved slots pointing elsewhere than the
// bound members.
TEST(VariableTable, ResolvedSlotsAndOnePassChecksSeeTheBoundMembers) {
  Holder h;
  EXPECT_TRUE(h.t.RealInputsFinite());
  EXPECT_TRUE(h.t.RealOutputsFinite());
  h.gain = std::numeric_limits<double>::quiet_NaN();  // a parameter
  h.state = std::numeric_limits<double>::infinity();  // a local
  EXPECT_TRUE(h.t.RealInputsFinite());
  EXPECT_TRUE(h.t.RealOutputsFinite());
  h.scan[2] = -std::numeric_limits<double>::infinity();
  EXPECT_FALSE(h.t.RealInputsFinite());
  EXPECT_TRUE(h.t.RealOutputsFinite());
  h.scan[2] = 3.0;
  h.speed = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(h.t.RealInputsFinite());
  h.speed = 1.0;
  h.force = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(h.t.RealOutputsFinite());
  EXPECT_TRUE(h.t.RealInputsFinite());

  const auto speed = h.t.ResolveWritableReal(h.speed_ref);
  EXPECT_EQ(speed.scalar, &h.speed);
  EXPECT_EQ(speed.array, nullptr);
  const auto scan = h.t.ResolveReal(h.scan_ref);
  EXPECT_EQ(scan.scalar, nullptr);
  EXPECT_EQ(scan.array, &h.scan);
  // Not a real: refused as the typed getters refuse it.
  EXPECT_THROW(h.t.ResolveReal(h.count_ref), std::logic_error);
  // Read-only: refused as the setters refuse it.
  h.t.Lock();
  EXPECT_THROW(h.t.ResolveWritableReal(h.gain_ref), std::logic_error);
  EXPECT_NO_THROW(h.t.ResolveReal(h.gain_ref));
}

// Guards against: unreadable values in messages (a list without brackets,
// a string without quotes, a real that does not read back).
TEST(FormatValue, RendersEveryType) {
  EXPECT_EQ(FormatValue(1.5), "1.5");
  EXPECT_EQ(FormatValue(0.1), "0.1");
  EXPECT_EQ(FormatValue(Value{std::int64_t{-7}}), "-7");
  EXPECT_EQ(FormatValue(Value{true}), "true");
  EXPECT_EQ(FormatValue(std::string("x")), "\"x\"");
  EXPECT_EQ(FormatValue(std::vector<double>{1.0, 2.5}), "[1, 2.5]");
  EXPECT_EQ(FormatValue(std::vector<double>{}), "[]");
}

// Guards against: enum names in messages drifting from the FMI terms.
TEST(VariableTable, EnumNames) {
  EXPECT_EQ(ToString(VarType::kRealArray), "Real[]");
  EXPECT_EQ(ToString(Causality::kParameter), "parameter");
  EXPECT_EQ(ToString(Variability::kTunable), "tunable");
}

}  // namespace
}  // namespace linesim::cosim
