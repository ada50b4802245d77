// System: endpoint parsing, every connection check of Build(), and the
// Gauss-Seidel dependency order.

#include "cosim/system.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "tests/cosim/test_units.h"

namespace linesim::cosim {
namespace {

using test_units::PassThrough;
using test_units::PortsUnit;
using ::testing::HasSubstr;

// Guards against: mis-splitting "unit.variable[index]" (wrong unit or
// variable, lost index).
TEST(Endpoint, ParsesUnitVariableAndIndex) {
  const Endpoint a = Endpoint::Parse("robot.speed");
  EXPECT_EQ(a.unit, "robot");
  EXPECT_EQ(a.variable, "speed");
  EXPECT_FALSE(a.index.has_value());
  EXPECT_EQ(a.ToString(), "robot.speed");

  const Endpoint b = Endpoint::Parse("laser_1.ranges[12]");
  EXPECT_EQ(b.unit, "laser_1");
  EXPECT_EQ(b.variable, "ranges");
  ASSERT_TRUE(b.index.has_value());
  EXPECT_EQ(*b.index, 12u);
  EXPECT_EQ(b.ToString(), "laser_1.ranges[12]");

  EXPECT_EQ(Endpoint::Parse("u.v[0]").index, 0u);

  // A fleet's robot scopes its units: the variable is after the last '.'.
  const Endpoint c = Endpoint::Parse("raw3_a.chassis.body_box[3]");
  EXPECT_EQ(c.unit, "raw3_a.chassis");
  EXPECT_EQ(c.variable, "body_box");
  EXPECT_EQ(c.index, 3u);
  EXPECT_EQ(c.ToString(), "raw3_a.chassis.body_box[3]");
}

// Guards against: accepting malformed endpoints (which would later fail as
// a confusing "unknown variable"), or throwing something other than
// std::invalid_argument (an index too large for size_t must not escape as
// std::out_of_range).
TEST(Endpoint, RefusesMalformedText) {
  for (const char* bad :
       {"", "nodot", ".v", "u.", "u.v[", "u.v[]", "u.v[x]", "u.v[-1]", "u.v[1]x", "u.v]", "a..c",
        "a.b.c[1].d", ".a.b",
        "u v.x", "u.v[1][2]", "u.v[99999999999999999999999999]"}) {
    try {
      Endpoint::Parse(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_THAT(e.what(), HasSubstr("expected unit.variable or unit.variable[index]")) << bad;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "'" << bad << "' threw a non-invalid_argument: " << e.what();
    }
  }
}

// Builds a system with PortsUnits named a, b, c and the given connections;
// returns the problems of Build() (empty when it succeeds).
std::vector<Problem> BuildProblems(const std::vector<std::pair<std::string, std::string>>& conns,
                                   System* out = nullptr) {
  System local;
  System& system = out ? *out : local;
  for (const char* n : {"a", "b", "c"}) system.Add(std::make_unique<PortsUnit>(n));
  for (const auto& [from, to] : conns) system.Connect(from, to);
  try {
    system.Build();
  } catch (const ConfigError& e) {
    return e.problems();
  }
  return {};
}

std::string OnlyMessage(const std::vector<Problem>& problems) {
  EXPECT_EQ(problems.size(), 1u);
  std::string all;
  for (const auto& p : problems) all += p.message + "\n";
  return all;
}

// Guards against: a typo in a unit name reported without the name that was
// meant. "robto" is one transposition from "robot".
TEST(SystemBuild, UnknownUnitSuggestsTheClosestName) {
  System system;
  system.Add(std::make_unique<PortsUnit>("robot"));
  system.Add(std::make_unique<PortsUnit>("belt"));
  system.Connect("robto.pos_out", "belt.pos");
  try {
    system.Build();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_EQ(e.problems()[0].message,
              "connection robto.pos_out -> belt.pos: unknown unit 'robto' (closest: robot)");
    EXPECT_EQ(e.problems()[0].connection, 0u);
  }
  EXPECT_FALSE(system.built());
}

// Guards against: a typo in a variable name reported without a suggestion.
TEST(SystemBuild, UnknownVariableSuggestsTheClosestName) {
  const std::string m = OnlyMessage(BuildProblems({{"a.pos_ot", "b.pos"}}));
  EXPECT_THAT(m, HasSubstr("unit 'a' (Ports) has no variable 'pos_ot'"));
  EXPECT_THAT(m, HasSubstr("(closest: pos_out"));
}

// Guards against: an index on a scalar being ignored (the whole scalar
// would be connected).
TEST(SystemBuild, IndexOnANonArray) {
  const std::string m = OnlyMessage(BuildProblems({{"a.pos_out", "b.pos[1]"}}));
  EXPECT_THAT(m, HasSubstr("b.pos[1]: pos is Real, not an array, so it takes no index"));
}

// Guards against: reading past the end of an array (scan_out has 3
// elements, valid indices 0..2).
TEST(SystemBuild, IndexOutOfRange) {
  const std::string m = OnlyMessage(BuildProblems({{"a.scan_out[3]", "b.pos"}}));
  EXPECT_THAT(m, HasSubstr("a.scan_out[3]: index out of range, scan_out has 3 elements"));
  EXPECT_TRUE(BuildProblems({{"a.scan_out[2]", "b.pos"}}).empty());
}

// Guards against: a Real silently copied into a Boolean. Both ends are
// dimensionless, so the type is the only problem.
TEST(SystemBuild, TypeMismatchRealToBoolean) {
  const std::string m = OnlyMessage(BuildProblems({{"a.ratio_out", "b.flag"}}));
  EXPECT_THAT(m, HasSubstr("type mismatch: a.ratio_out is Real, b.flag is Boolean"));
}

// Guards against: copying 4 elements into a 3-element array.
TEST(SystemBuild, ArraySizeMismatch) {
  const std::string m = OnlyMessage(BuildProblems({{"a.scan4_out", "b.scan"}}));
  EXPECT_THAT(m, HasSubstr("array size mismatch: a.scan4_out has 4 elements, b.scan has 3"));
  EXPECT_TRUE(BuildProblems({{"a.scan_out", "b.scan"}}).empty());
}

// Guards against: connections that run the wrong way (from an input, or
// into an output, which the unit would overwrite).
TEST(SystemBuild, WrongCausality) {
  EXPECT_THAT(OnlyMessage(BuildProblems({{"a.pos", "b.pos"}})),
              HasSubstr("a.pos is input, a connection must go from an output to an input"));
  EXPECT_THAT(OnlyMessage(BuildProblems({{"a.pos_out", "b.pos_out"}})),
              HasSubstr("b.pos_out is output, a connection must go from an output to an input"));
  EXPECT_THAT(OnlyMessage(BuildProblems({{"a.gain", "b.pos"}})), HasSubstr("a.gain is parameter"));
}

// Guards variability at the system level: a parameter keeps its value over
// the run, so no signal may drive it; the message says where it is set.
TEST(SystemBuild, AConnectionIntoAParameterIsRefused) {
  EXPECT_THAT(OnlyMessage(BuildProblems({{"a.pos_out", "b.gain"}})),
              HasSubstr("connection a.pos_out -> b.gain: b.gain is a parameter: parameters are "
                        "set before the run (under parameters:), not connected"));
}

// Guards against: a speed in m/s fed into a position input in m.
TEST(SystemBuild, DifferentUnitsOfMeasure) {
  const std::string m = OnlyMessage(BuildProblems({{"a.speed_out", "b.pos"}}));
  EXPECT_THAT(m, HasSubstr("units of measure differ: a.speed_out is in 'm/s', b.pos is in 'm'"));
}

// Guards against: two outputs writing one input (the last transfer would
// win silently), also for one element of an array and for a whole array
// plus one of its elements; two different elements of one array are fine.
TEST(SystemBuild, InputWithTwoSources) {
  const auto whole = BuildProblems({{"a.pos_out", "c.pos"}, {"b.pos_out", "c.pos"}});
  ASSERT_EQ(whole.size(), 1u);
  EXPECT_EQ(whole[0].message, "input c.pos has two sources: a.pos_out and b.pos_out");
  EXPECT_EQ(whole[0].connection, 1u);

  EXPECT_THAT(
      OnlyMessage(BuildProblems({{"a.scan_out[0]", "c.scan[1]"}, {"b.scan_out[2]", "c.scan[1]"}})),
      HasSubstr("input c.scan[1] has two sources: a.scan_out[0] and b.scan_out[2]"));
  EXPECT_THAT(OnlyMessage(BuildProblems({{"a.scan_out", "c.scan"}, {"b.pos_out", "c.scan[2]"}})),
              HasSubstr("input c.scan[2] has two sources: a.scan_out and b.pos_out"));
  EXPECT_TRUE(BuildProblems({{"a.scan_out[0]", "c.scan[0]"},
                             {"b.scan_out[0]", "c.scan[1]"},
                             {"a.pos_out", "c.scan[2]"}})
                  .empty());
}

// Guards against: a bad unit list (name that cannot appear in an endpoint,
// duplicate names, negative step) being accepted.
TEST(SystemBuild, BadUnitNamesAndSteps) {
  System system;
  system.Add(std::make_unique<PortsUnit>("a b"));
  system.Add(std::make_unique<PortsUnit>("twin"));
  system.Add(std::make_unique<PortsUnit>("twin"));
  system.Add(std::make_unique<PortsUnit>("late"), -1'000'000);
  try {
    system.Build();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.problems().size(), 3u) << e.what();
    EXPECT_EQ(e.problems()[0].message,
              "unit name 'a b' is not valid: use letters, digits and '_' (and '.' after a scope)");
    EXPECT_EQ(e.problems()[1].message, "two units are named 'twin'");
    EXPECT_EQ(e.problems()[2].message, "unit 'late' has a negative step");
  }
}

std::unique_ptr<System> Ring(bool b_has_feedthrough) {
  auto s = std::make_unique<System>();
  s->Add(std::make_unique<PassThrough>("a", true));
  s->Add(std::make_unique<PassThrough>("b", b_has_feedthrough));
  s->Add(std::make_unique<PassThrough>("c", true));
  s->Connect("a.y", "b.u");
  s->Connect("b.y", "c.u");
  s->Connect("c.y", "a.u");
  return s;
}

// Guards against: an algebraic loop going unnoticed (a fixed-step master
// would then solve it with a silent one-step delay), or being reported
// without the cycle. Every hop of the ring a -> b -> c -> a, inside the
// units and between them, must appear in the message, in cycle order.
TEST(SystemBuild, AlgebraicLoopNamesTheCycle) {
  auto s = Ring(true);
  try {
    s->Build();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.problems().size(), 1u) << e.what();
    const std::string& m = e.problems()[0].message;
    EXPECT_THAT(m, HasSubstr("algebraic loop"));
    for (const char* hop :
         {"a.u -> a.y", "a.y -> b.u", "b.u -> b.y", "b.y -> c.u", "c.u -> c.y", "c.y -> a.u"}) {
      EXPECT_THAT(m, HasSubstr(hop));
    }
  }
}

// Guards against: a false alarm on a feedback loop that a unit's state
// breaks (b has no direct feedthrough): that ring is a valid system.
TEST(SystemBuild, RingBrokenByAUnitWithoutFeedthroughIsAccepted) {
  auto s = Ring(false);
  EXPECT_NO_THROW(s->Build());
  EXPECT_TRUE(s->built());
  ASSERT_EQ(s->links().size(), 3u);
}

// Guards against: Build stopping at the first problem. One system with an
// unknown unit, an unknown variable, a type mismatch, different units, an
// input with two sources and a wrong causality: all six in one ConfigError,
// each pointing at its connection.
TEST(SystemBuild, ReportsEveryProblemAtOnce) {
  const auto problems = BuildProblems({
      {"x.pos_out", "b.pos"},      // 0: unknown unit
      {"a.speed_ot", "b.speed"},   // 1: unknown variable
      {"a.ratio_out", "b.flag"},   // 2: type mismatch
      {"a.speed_out", "c.pos"},    // 3: units of measure
      {"a.count_out", "c.count"},  // 4: fine alone ...
      {"b.count_out", "c.count"},  // 5: ... but a second source
      {"a.pos", "c.speed"},        // 6: from an input
  });
  ASSERT_EQ(problems.size(), 6u);
  std::string all;
  for (const auto& p : problems) all += p.message + "\n";
  EXPECT_THAT(all, HasSubstr("unknown unit 'x'"));
  EXPECT_THAT(all, HasSubstr("no variable 'speed_ot' (closest: speed_out"));
  EXPECT_THAT(all, HasSubstr("type mismatch"));
  EXPECT_THAT(all, HasSubstr("units of measure differ"));
  EXPECT_THAT(all, HasSubstr("input c.count has two sources"));
  EXPECT_THAT(all, HasSubstr("a.pos is input"));
  std::vector<std::size_t> where;
  for (const auto& p : problems) {
    ASSERT_TRUE(p.connection.has_value());
    where.push_back(*p.connection);
  }
  std::sort(where.begin(), where.end());
  EXPECT_EQ(where, (std::vector<std::size_t>{0, 1, 2, 3, 5, 6}));
}

// Guards against: the loop check and the connection checks excluding each
// other; a system with a bad connection and an algebraic loop reports both.
TEST(SystemBuild, ReportsConnectionProblemsAndAlgebraicLoopTogether) {
  auto s = Ring(true);
  s->Connect("a.y", "nobody.u");
  try {
    s->Build();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.problems().size(), 2u) << e.what();
    EXPECT_THAT(e.what(), HasSubstr("unknown unit 'nobody'"));
    EXPECT_THAT(e.what(), HasSubstr("algebraic loop"));
  }
}

// Guards against: resolved links pointing at the wrong unit, variable or
// element.
TEST(SystemBuild, LinksResolveUnitsRefsAndElements) {
  System system;
  ASSERT_TRUE(
      BuildProblems(
          {{"a.scan_out[2]", "b.pos"}, {"b.pos_out", "c.scan[1]"}, {"a.scan_out", "b.scan"}},
          &system)
          .empty());
  const auto& l = system.links();
  ASSERT_EQ(l.size(), 3u);
  const auto& ta = system.unit(0).variables();
  const auto& tb = system.unit(1).variables();
  EXPECT_EQ(l[0].from_unit, 0u);
  EXPECT_EQ(l[0].to_unit, 1u);
  EXPECT_EQ(l[0].from_ref, *ta.Find("scan_out"));
  EXPECT_EQ(l[0].to_ref, *tb.Find("pos"));
  EXPECT_EQ(l[0].from_index, 2);
  EXPECT_EQ(l[0].to_index, -1);
  EXPECT_EQ(l[0].type, VarType::kReal);
  EXPECT_EQ(l[1].to_index, 1);
  EXPECT_EQ(l[1].type, VarType::kReal);
  EXPECT_EQ(l[2].type, VarType::kRealArray);
}

// Guards against: Resolve accepting names Build would refuse.
TEST(SystemResolve, ResolvesAndExplains) {
  System system;
  ASSERT_TRUE(BuildProblems({}, &system).empty());
  const auto r = system.Resolve("b.scan_out[1]");
  EXPECT_EQ(r.unit, 1u);
  EXPECT_EQ(r.ref, *system.unit(1).variables().Find("scan_out"));
  EXPECT_EQ(r.index, 1);
  EXPECT_EQ(system.Resolve("c.pos").index, -1);
  EXPECT_THROW(system.Resolve("bad"), ConfigError);
  try {
    system.Resolve("d.pos");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown unit 'd'"));
  }
  try {
    system.Resolve("a.speeed");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no variable 'speeed' (closest: speed"));
  }
  try {
    system.Resolve("a.scan_out[3]");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("index out of range, scan_out has 3 elements"));
  }
  try {
    system.Resolve("a.pos[0]");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("pos is not an array"));
  }
}

// Guards against: Gauss-Seidel stepping a unit before the unit that feeds
// it. Chain first -> second -> third declared in reverse: order must be
// source first (unit indices 2, 1, 0).
TEST(SystemOrder, ChainDeclaredInReverseIsOrderedSourceFirst) {
  System s;
  s.Add(std::make_unique<PassThrough>("third", false));
  s.Add(std::make_unique<PassThrough>("second", true));
  s.Add(std::make_unique<PassThrough>("first", false));
  s.Connect("second.y", "third.u");
  s.Connect("first.y", "second.u");
  s.Build();
  EXPECT_EQ(s.dependency_order(), (std::vector<std::size_t>{2, 1, 0}));
}

// Guards against: ordering a feedback loop by declaration. In the loop
// plant (no feedthrough) <-> controller (feedthrough), the controller must
// come after the plant that feeds it, even when declared first; an
// unconnected unit keeps its declaration place among the ready units.
TEST(SystemOrder, InsideAFeedbackLoopFeedthroughUnitComesAfterItsSource) {
  System s;
  s.Add(std::make_unique<PassThrough>("controller", true));
  s.Add(std::make_unique<PassThrough>("plant", false));
  s.Add(std::make_unique<PassThrough>("idle", false));
  s.Connect("controller.y", "plant.u");
  s.Connect("plant.y", "controller.u");
  s.Build();
  EXPECT_EQ(s.dependency_order(), (std::vector<std::size_t>{1, 0, 2}));
}

// Guards against: a system marked built after it changed.
TEST(SystemBuild, AddingAConnectionClearsBuilt) {
  System s;
  s.Add(std::make_unique<PassThrough>("a", false));
  s.Add(std::make_unique<PassThrough>("b", false));
  s.Build();
  EXPECT_TRUE(s.built());
  s.Connect("a.y", "b.u");
  EXPECT_FALSE(s.built());
}

}  // namespace
}  // namespace linesim::cosim
