// Observers: probe resolution, the CSV recorder and the metrics reductions.

#include "cosim/observers.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "tests/cosim/test_units.h"

namespace linesim::cosim {
namespace {

using test_units::PortsUnit;
using test_units::RampSource;
using ::testing::HasSubstr;

constexpr TimeNs kMs = 1'000'000;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::vector<std::string> Labels(const std::vector<Probe>& probes) {
  std::vector<std::string> out;
  for (const auto& p : probes) out.push_back(p.label);
  return out;
}

// Guards against: a whole array recorded as one column (or not at all), and
// "unit.*" picking up inputs, parameters, locals or strings.
TEST(ResolveProbes, ExpandsArraysAndWildcards) {
  System system;
  system.Add(std::make_unique<PortsUnit>("p"));
  system.Build();
  EXPECT_EQ(Labels(ResolveProbes(system, {"p.scan_out"})),
            (std::vector<std::string>{"p.scan_out[0]", "p.scan_out[1]", "p.scan_out[2]"}));
  EXPECT_EQ(Labels(ResolveProbes(system, {"p.scan4_out[3]", "p.pos"})),
            (std::vector<std::string>{"p.scan4_out[3]", "p.pos"}));
  EXPECT_EQ(Labels(ResolveProbes(system, {"p.*"})),
            (std::vector<std::string>{"p.pos_out", "p.speed_out", "p.ratio_out", "p.flag_out",
                                      "p.count_out", "p.scan_out[0]", "p.scan_out[1]",
                                      "p.scan_out[2]", "p.scan4_out[0]", "p.scan4_out[1]",
                                      "p.scan4_out[2]", "p.scan4_out[3]"}));
}

// Guards against: a recording request failing on its first bad name only,
// or without saying what was meant. Six bad names (one of the seven is
// good), six problems.
TEST(ResolveProbes, ReportsEveryBadNameAtOnce) {
  System system;
  system.Add(std::make_unique<PortsUnit>("robot"));
  system.Build();
  try {
    ResolveProbes(system, {"robto.pos_out", "robot.pos_ot", "robot.scan_out[3]", "robot.label",
                           "rboot.*", "robot.pos_out", "garbage"});
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.problems().size(), 6u) << e.what();
    EXPECT_THAT(e.problems()[0].message, HasSubstr("unknown unit 'robto'"));
    EXPECT_THAT(e.problems()[0].message, HasSubstr("(closest: robot)"));
    EXPECT_THAT(e.problems()[1].message, HasSubstr("no variable 'pos_ot' (closest: "));
    EXPECT_THAT(e.problems()[1].message, HasSubstr("pos_out"));
    EXPECT_THAT(e.problems()[2].message, HasSubstr("index out of range"));
    EXPECT_THAT(e.problems()[3].message, HasSubstr("strings are not numbers"));
    EXPECT_THAT(e.problems()[4].message, HasSubstr("unknown unit 'rboot' in 'rboot.*'"));
    EXPECT_THAT(e.problems()[5].message, HasSubstr("'garbage' is not an endpoint"));
  }
}

// Guards against: a malformed header, floating-point time stamps
// ("0.30000000000000004") or lossy values. A ramp value = t over 1 s at a
// 1 ms base step: 1001 rows, time column the exact decimal of k ms, value
// column the shortest round-trip form of k / 1000, i.e. the same digits.
TEST(CsvRecorder, HeaderAndRowsWithExactDecimalTime) {
  System system;
  system.Add(std::make_unique<RampSource>("ramp"));
  std::ostringstream csv;
  CsvRecorder recorder(csv, ResolveProbes(system, {"ramp.value"}));
  MasterOptions o;
  o.base_step = kMs;
  o.stop = 1000 * kMs;
  Master master(system, o);
  master.AddObserver(&recorder);
  ASSERT_TRUE(master.Run().ok);
  const auto lines = Lines(csv.str());
  ASSERT_EQ(lines.size(), 1002u);
  EXPECT_EQ(recorder.rows(), 1001);
  EXPECT_EQ(lines[0], "time,ramp.value");
  EXPECT_EQ(lines[1], "0,0");
  EXPECT_EQ(lines[2], "0.001,0.001");
  EXPECT_EQ(lines[301], "0.3,0.3");
  EXPECT_EQ(lines[1001], "1,1");
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const std::string time = lines[k].substr(0, lines[k].find(','));
    const std::string value = lines[k].substr(lines[k].find(',') + 1);
    ASSERT_EQ(time, value) << "row " << k;
    ASSERT_LE(time.size(), 5u) << "row " << k;  // "0.123": never more than 3 decimals
  }
}

// Guards against: wrong column order or values for integers, booleans and
// array elements. PortsUnit start values: count_out 7, flag_out true (1),
// scan_out {1, 2, 3}; the unit never changes them.
TEST(CsvRecorder, RecordsEveryTypeAsNumbers) {
  System system;
  system.Add(std::make_unique<PortsUnit>("u"));
  std::ostringstream csv;
  CsvRecorder recorder(csv, ResolveProbes(system, {"u.count_out", "u.flag_out", "u.scan_out"}));
  MasterOptions o;
  o.base_step = kMs;
  o.stop = kMs;
  Master master(system, o);
  master.AddObserver(&recorder);
  ASSERT_TRUE(master.Run().ok);
  EXPECT_EQ(csv.str(),
            "time,u.count_out,u.flag_out,u.scan_out[0],u.scan_out[1],u.scan_out[2]\n"
            "0,7,1,1,2,3\n"
            "0.001,7,1,1,2,3\n");
}

// Guards against: the decimation interval being ignored or counted from 0
// instead of the start time. Start 0.501 s (not a multiple of the
// interval), stop 0.521 s, base 1 ms, interval 4 ms: rows at 0.501, 0.505,
// ..., 0.521 (6 rows).
TEST(CsvRecorder, DecimationInterval) {
  System system;
  system.Add(std::make_unique<RampSource>("ramp"));
  std::ostringstream csv;
  CsvRecorder recorder(csv, ResolveProbes(system, {"ramp.value"}), 4 * kMs);
  MasterOptions o;
  o.base_step = kMs;
  o.start = 501 * kMs;
  o.stop = 521 * kMs;
  Master master(system, o);
  master.AddObserver(&recorder);
  ASSERT_TRUE(master.Run().ok);
  EXPECT_EQ(csv.str(),
            "time,ramp.value\n0.501,0.501\n0.505,0.505\n0.509,0.509\n0.513,0.513\n"
            "0.517,0.517\n0.521,0.521\n");
}

// Guards against a recording that silently writes no rows: an interval that
// is not a multiple of the master step is refused when the run starts.
TEST(CsvRecorder, RefusesAnIntervalOffTheMasterSteps) {
  System system;
  system.Add(std::make_unique<RampSource>("ramp"));
  std::ostringstream csv;
  CsvRecorder recorder(csv, ResolveProbes(system, {"ramp.value"}), 3 * kMs / 2);
  MasterOptions o;
  o.base_step = kMs;
  o.stop = 6 * kMs;
  Master master(system, o);
  master.AddObserver(&recorder);
  // The run fails with the reason, like a unit failure (no exception
  // escapes, the units are terminated).
  const RunResult r = master.Run();
  EXPECT_FALSE(r.ok);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_THAT(r.errors[0].message, HasSubstr("observer at start"));
}

std::vector<MetricSpec> RampMetrics(const System& system) {
  const Probe probe = ResolveProbes(system, {"ramp.value"}).front();
  std::vector<MetricSpec> specs;
  for (const std::string& name : ReductionNames()) {
    Reduction r;
    EXPECT_TRUE(ParseReduction(name, &r));
    specs.push_back({name, probe, r});
  }
  return specs;
}

// Guards against: wrong reductions (mean over time instead of samples, rms
// without the square root, min/max seeded with 0, max_abs losing the sign).
// Signal: v = t - 0.75 (s) sampled at t_k = k ms, k = 0 .. 1000 (1001
// samples). Analytic: final 0.25, min -0.75, max 0.25, max_abs 0.75,
// mean = (500.5 - 750.75) / 1001 = -0.25,
// rms^2 = (sum (k/1000)^2 - 1.5 sum k/1000 + 1001 * 0.5625) / 1001
//       = (333.8335 - 750.75 + 563.0625) / 1001 = 146.146 / 1001 = 0.146.
TEST(MetricsObserver, ReductionsOfARamp) {
  System system;
  system.Add(std::make_unique<RampSource>("ramp", 1.0, -0.75));
  system.Build();
  MetricsObserver metrics(RampMetrics(system));
  MasterOptions o;
  o.base_step = kMs;
  o.stop = 1000 * kMs;
  Master master(system, o);
  master.AddObserver(&metrics);
  ASSERT_TRUE(master.Run().ok);
  const auto results = metrics.Results();
  ASSERT_EQ(results.size(), 6u);
  const std::vector<std::pair<std::string, double>> expected = {
      {"final", 0.25},   {"min", -0.75},  {"max", 0.25},
      {"max_abs", 0.75}, {"mean", -0.25}, {"rms", std::sqrt(0.146)}};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(results[i].first, expected[i].first);
    EXPECT_NEAR(results[i].second, expected[i].second, 1e-12) << expected[i].first;
  }
}

// Guards against: a metric of an empty run reading as 0 (a plausible
// number) instead of NaN.
TEST(MetricsObserver, NoSamplesGivesNaN) {
  System system;
  system.Add(std::make_unique<RampSource>("ramp"));
  system.Build();
  MetricsObserver metrics(RampMetrics(system));
  for (const auto& [name, value] : metrics.Results()) EXPECT_TRUE(std::isnan(value)) << name;
}

// Guards against: a typo in a scenario's reduction name being accepted.
TEST(ParseReduction, KnownAndUnknownNames) {
  Reduction r = Reduction::kFinal;
  EXPECT_TRUE(ParseReduction("max_abs", &r));
  EXPECT_EQ(r, Reduction::kMaxAbs);
  EXPECT_FALSE(ParseReduction("average", &r));
  EXPECT_FALSE(ParseReduction("RMS", &r));
  EXPECT_EQ(r, Reduction::kMaxAbs);
}

}  // namespace
}  // namespace linesim::cosim
