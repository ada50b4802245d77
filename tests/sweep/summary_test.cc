#include "sweep/summary.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cosim/variable_table.h"

namespace linesim::sweep {
namespace {

namespace fs = std::filesystem;
using Row = SweepTable::Row;

// The seed is 100 + id, to check that failures carry theirs.
Row Ok(std::int64_t id, std::vector<std::string> values, std::vector<double> metrics) {
  return {.id = id,
          .values = std::move(values),
          .seed = static_cast<std::uint64_t>(100 + id),
          .ok = true,
          .metrics = std::move(metrics),
          .error = "",
          .error_unit = "",
          .error_time_s = std::nullopt,
          .error_phase = "",
          .error_variable = "",
          .error_cause = ""};
}

Row Failed(std::int64_t id, std::vector<std::string> values, std::string error,
           std::vector<double> metrics = {NAN, NAN}) {
  return {.id = id,
          .values = std::move(values),
          .seed = static_cast<std::uint64_t>(100 + id),
          .ok = false,
          .metrics = std::move(metrics),
          .error = std::move(error),
          .error_unit = "chassis",
          .error_time_s = 3.2,
          .error_phase = "step",
          .error_variable = "pose[0]",
          .error_cause = "output 'pose[0]' is nan"};
}

// Belt speed x compensation, two repeats; at 0.1 m/s without compensation
// both runs fail (run 3 with values that must not count, as a run that
// fails after its metrics were taken would have). The numbers are small
// integers so that every statistic below is worked out by hand in its test.
SweepTable Grid() {
  SweepTable t;
  t.name = "crossing";
  t.parameters = {"line.belts.0.speed_mps", "control.compensation"};
  t.levels = {{"0.05", "0.1"}, {"true", "false"}};
  t.metrics = {"max_deviation_m", "wall_s"};
  t.rows = {
      Ok(0, {"0.05", "true"}, {1, 10}),
      Ok(1, {"0.05", "false"}, {2, 10}),
      Ok(2, {"0.1", "true"}, {4, 10}),
      Failed(3, {"0.1", "false"}, "chassis: output 'pose[0]' is nan at t = 3.2 s", {100, 100}),
      Ok(4, {"0.05", "true"}, {3, 12}),
      Ok(5, {"0.05", "false"}, {4, 12}),
      Ok(6, {"0.1", "true"}, {5, 12}),
      Failed(7, {"0.1", "false"}, "chassis: output 'pose[0]' is nan at t = 2.9 s")};
  return t;
}

// A Monte-Carlo draw of the belt's speed variation: the deviation is
// exactly 2 x + 1, the wall time constant; the run at 0.5 fails (with
// values that must not count).
SweepTable Random() {
  SweepTable t;
  t.name = "variation";
  t.parameters = {"line.belts.0.speed_variation"};
  t.levels = {{}};
  t.metrics = {"max_deviation_m", "wall_s"};
  t.grid = false;
  t.rows = {Ok(0, {"0.3"}, {1.6, 5}), Ok(1, {"0.1"}, {1.2, 5}),
            Failed(2, {"0.5"}, "diverged", {9, 9}), Ok(3, {"0.4"}, {1.8, 5}),
            Ok(4, {"0.2"}, {1.4, 5})};
  return t;
}

// Guards the arithmetic: sample standard deviation (n - 1) of {1, 2, 4}:
// mean 7/3, squared deviations 16/9 + 1/9 + 25/9 = 14/3, / 2 = 7/3, so
// std = sqrt(7/3).
TEST(StatsOf, MeanSampleStdAndExtremes) {
  const std::vector<double> values{1, 2, 4};
  const Stats s = StatsOf(values);
  EXPECT_EQ(s.n, 3);
  EXPECT_DOUBLE_EQ(s.mean, 7.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(7.0 / 3.0));
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 4.0);
}

// Guards paper 2's Table 1 figures: the largest and the mean absolute
// value of signed errors (worked by hand: |-3| is the largest, (1+2+3)/3).
TEST(StatsOf, LargestAndMeanAbsoluteValue) {
  const std::vector<double> values{1, -3, 2};
  const Stats s = StatsOf(values);
  EXPECT_EQ(s.max_abs, 3.0);
  EXPECT_DOUBLE_EQ(s.mean_abs, 2.0);
  EXPECT_TRUE(std::isnan(StatsOf({}).max_abs));
}

// Guards the edge cases: one value has std 0 (not NaN from 0/0), none has
// NaN everywhere, and non-finite values are not counted.
TEST(StatsOf, OneValueNoValueAndNonFinite) {
  const std::vector<double> one{2.5};
  EXPECT_EQ(StatsOf(one).std, 0.0);
  EXPECT_EQ(StatsOf(one).mean, 2.5);
  const Stats none = StatsOf({});
  EXPECT_EQ(none.n, 0);
  EXPECT_TRUE(std::isnan(none.mean) && std::isnan(none.std));
  EXPECT_TRUE(std::isnan(none.min) && std::isnan(none.max));
  const std::vector<double> with_nan{1, NAN, 3, INFINITY};
  const Stats s = StatsOf(with_nan);
  EXPECT_EQ(s.n, 2);
  EXPECT_EQ(s.mean, 2.0);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(2.0));  // (1 + 1) / 1
}

// Guards Pearson's r: exactly linear data give +1 or -1, and it is
// undefined (NaN, not 0 or a division error) for a constant side or a
// single pair.
TEST(Correlation, LinearConstantAndTooFew) {
  const std::vector<double> x{0.1, 0.2, 0.3, 0.4}, up{1.2, 1.4, 1.6, 1.8}, down{4, 3, 2, 1};
  const std::vector<double> flat{5, 5, 5, 5};
  EXPECT_DOUBLE_EQ(Correlation(x, up), 1.0);
  EXPECT_DOUBLE_EQ(Correlation(x, down), -1.0);
  EXPECT_TRUE(std::isnan(Correlation(x, flat)));
  EXPECT_TRUE(std::isnan(Correlation(std::vector<double>{1}, std::vector<double>{2})));
}

// Guards the totals and the per-value groups: failed runs are counted per
// group and left out of the statistics. Speed 0.05: deviations {1, 2, 3, 4}
// (mean 2.5, squared deviations 5, std sqrt(5/3)); speed 0.1: {4, 5} of 4
// runs, 2 failed (mean 4.5, std sqrt(1/2)).
TEST(Summarize, GroupsByParameterValueWithoutFailedRuns) {
  const auto s = Summarize(Grid());
  EXPECT_EQ(s["name"], "crossing");
  EXPECT_EQ(s["runs"], 8);
  EXPECT_EQ(s["ok"], 6);
  EXPECT_EQ(s["failed"], 2);
  EXPECT_EQ(s["parameters"][1], "control.compensation");
  EXPECT_EQ(s["metrics"][1], "wall_s");
  const auto& speed = s["by_parameter"]["line.belts.0.speed_mps"];
  ASSERT_EQ(speed.size(), 2u);
  EXPECT_EQ(speed[0]["value"], "0.05");
  EXPECT_EQ(speed[0]["runs"], 4);
  EXPECT_EQ(speed[0]["failed"], 0);
  const auto& slow = speed[0]["metrics"]["max_deviation_m"];
  EXPECT_EQ(slow["n"], 4);
  EXPECT_DOUBLE_EQ(slow["mean"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(slow["std"].get<double>(), std::sqrt(5.0 / 3.0));
  EXPECT_EQ(slow["min"], 1.0);
  EXPECT_EQ(slow["max"], 4.0);
  EXPECT_EQ(speed[1]["value"], "0.1");
  EXPECT_EQ(speed[1]["runs"], 4);
  EXPECT_EQ(speed[1]["failed"], 2);
  const auto& fast = speed[1]["metrics"]["max_deviation_m"];
  EXPECT_EQ(fast["n"], 2);
  EXPECT_DOUBLE_EQ(fast["mean"].get<double>(), 4.5);
  EXPECT_DOUBLE_EQ(fast["std"].get<double>(), std::sqrt(0.5));
  // Values keep their YAML text, booleans included.
  EXPECT_EQ(s["by_parameter"]["control.compensation"][0]["value"], "true");
  EXPECT_EQ(s["by_parameter"]["control.compensation"][1]["failed"], 2);
}

// Guards the order of the groups: the parameter's levels (plan order), not
// the order the runs finished in, and a level without runs still listed.
TEST(Summarize, GroupsFollowTheLevels) {
  SweepTable t;
  t.parameters = {"master.algorithm"};
  t.levels = {{"gauss_seidel", "jacobi", "unused"}};
  t.metrics = {"wall_s"};
  t.rows = {Ok(0, {"jacobi"}, {2}), Ok(1, {"gauss_seidel"}, {1})};
  const auto s = Summarize(t);
  const auto& groups = s["by_parameter"]["master.algorithm"];
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_EQ(groups[0]["value"], "gauss_seidel");
  EXPECT_EQ(groups[1]["value"], "jacobi");
  EXPECT_EQ(groups[2]["value"], "unused");
  EXPECT_EQ(groups[2]["runs"], 0);
}

// Guards by_point: one entry per combination across repeats, in first-seen
// order; (0.05, true) holds runs 0 and 4: {1, 3}, mean 2, std sqrt(2). The
// combination whose runs all failed has n 0 and nulls, not NaN or 0.
TEST(Summarize, ByPointGroupsRepeatsAndNullsEmptyStats) {
  const auto s = Summarize(Grid());
  const auto& points = s["by_point"];
  ASSERT_EQ(points.size(), 4u);
  EXPECT_EQ(points[0]["values"]["line.belts.0.speed_mps"], "0.05");
  EXPECT_EQ(points[0]["values"]["control.compensation"], "true");
  EXPECT_EQ(points[0]["runs"], 2);
  const auto& first = points[0]["metrics"]["max_deviation_m"];
  EXPECT_EQ(first["mean"], 2.0);
  EXPECT_DOUBLE_EQ(first["std"].get<double>(), std::sqrt(2.0));
  EXPECT_EQ(points[1]["values"]["control.compensation"], "false");
  EXPECT_EQ(points[3]["values"]["line.belts.0.speed_mps"], "0.1");
  EXPECT_EQ(points[3]["values"]["control.compensation"], "false");
  EXPECT_EQ(points[3]["runs"], 2);
  EXPECT_EQ(points[3]["failed"], 2);
  const auto& none = points[3]["metrics"]["max_deviation_m"];
  EXPECT_EQ(none["n"], 0);
  for (const char* key : {"mean", "std", "min", "max"}) EXPECT_TRUE(none[key].is_null()) << key;
}

// Guards the failure list: every failed run with its id, seed (to rerun
// it), values and error (its fields and message).
TEST(Summarize, ListsFailures) {
  const auto failures = Summarize(Grid())["failures"];
  ASSERT_EQ(failures.size(), 2u);
  EXPECT_EQ(failures[0]["id"], 3);
  EXPECT_EQ(failures[0]["seed"], 103);
  EXPECT_EQ(failures[0]["values"]["line.belts.0.speed_mps"], "0.1");
  EXPECT_EQ(failures[0]["values"]["control.compensation"], "false");
  // The error as data, the same object as `linesim run` writes, with the
  // whole message.
  const auto& error = failures[0]["error"];
  EXPECT_EQ(error["message"], "chassis: output 'pose[0]' is nan at t = 3.2 s");
  EXPECT_EQ(error["unit"], "chassis");
  EXPECT_EQ(error["time_s"], 3.2);
  EXPECT_EQ(error["phase"], "step");
  EXPECT_EQ(error["variable"], "pose[0]");
  EXPECT_EQ(error["cause"], "output 'pose[0]' is nan");
  EXPECT_EQ(failures[1]["id"], 7);
}

// Guards the random-parameter summary: range over all runs (the failed one
// at 0.5 included), correlation over ok runs (2 x + 1 gives exactly 1), null
// when undefined (constant wall time); no per-point groups outside a grid.
TEST(Summarize, RandomParameterHasRangeAndCorrelation) {
  const auto s = Summarize(Random());
  const auto& p = s["by_parameter"]["line.belts.0.speed_variation"];
  ASSERT_TRUE(p.is_object());
  EXPECT_EQ(p["min"], 0.1);
  EXPECT_EQ(p["max"], 0.5);
  EXPECT_DOUBLE_EQ(p["correlation"]["max_deviation_m"].get<double>(), 1.0);
  EXPECT_TRUE(p["correlation"]["wall_s"].is_null());
  EXPECT_FALSE(s.contains("by_point"));
  EXPECT_EQ(s["failed"], 1);
}

// Guards against reading past a row's values or metrics: a table whose rows
// do not match its header is refused, naming the run.
TEST(Summarize, RowOfTheWrongShapeIsRefused) {
  SweepTable t = Grid();
  t.rows[5].values.pop_back();
  try {
    Summarize(t);
    FAIL() << "a row with one value for two parameters was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("run 5 has 1 values"), std::string::npos) << e.what();
  }
}

// Guards the terminal table: per parameter and value, each metric's mean ±
// std [min, max] to 4 significant digits, aligned, then the failures.
// Numbers by hand: speed 0.05 wall times {10, 10, 12, 12}: mean 11, std
// sqrt(4/3) = 1.155; compensation=true deviations {1, 4, 3, 5}: mean 3.25,
// squared deviations 8.75, std sqrt(8.75/3) = 1.708.
TEST(PrintSummary, AlignedTablePerParameterThenPerPointThenFailures) {
  std::ostringstream out;
  PrintSummary(Grid(), out);
  const std::string expected =
      "sweep crossing: 8 runs, 6 ok, 2 failed\n"
      "\n"
      "line.belts.0.speed_mps\n"
      "  value  runs  failed  metric           mean  ± std     [min, max]\n"
      "  0.05      4       0  max_deviation_m   2.5  ± 1.291   [1, 4]\n"
      "                       wall_s             11  ± 1.155   [10, 12]\n"
      "  0.1       4       2  max_deviation_m   4.5  ± 0.7071  [4, 5]\n"
      "                       wall_s             11  ± 1.414   [10, 12]\n"
      "\n"
      "control.compensation\n"
      "  value  runs  failed  metric           mean  ± std    [min, max]\n"
      "  true      4       0  max_deviation_m  3.25  ± 1.708  [1, 5]\n"
      "                       wall_s             11  ± 1.155  [10, 12]\n"
      "  false     4       2  max_deviation_m     3  ± 1.414  [2, 4]\n"
      "                       wall_s             11  ± 1.414  [10, 12]\n"
      "\n"
      // Per point, mean over repeats: (0.05, true) from 1 and 3, and so on;
      // the point whose runs all failed has none.
      "per point (mean over ok runs)\n"
      "  line.belts.0.speed_mps  control.compensation  runs  failed  max_deviation_m  wall_s\n"
      "  0.05                    true                     2       0                2      11\n"
      "  0.05                    false                    2       0                3      11\n"
      "  0.1                     true                     2       0              4.5      11\n"
      "  0.1                     false                    2       2                -       -\n"
      "\n"
      "failed runs:\n"
      "  run 3 (line.belts.0.speed_mps=0.1, control.compensation=false): chassis: output "
      "'pose[0]' is nan at t = 3.2 s\n"
      "  run 7 (line.belts.0.speed_mps=0.1, control.compensation=false): chassis: output "
      "'pose[0]' is nan at t = 2.9 s\n";
  EXPECT_EQ(out.str(), expected);
}

// Guards against a terminal flooded by a sweep that fails everywhere: at
// most 10 failures, then how many more; a value without ok runs says so;
// a random parameter prints its range and correlations.
TEST(PrintSummary, FailuresCappedAndRandomParameters) {
  SweepTable t = Random();
  for (int k = 0; k < 11; ++k) t.rows.push_back(Failed(10 + k, {"0.9"}, "line one\nline two"));
  std::ostringstream out;
  PrintSummary(t, out);
  const std::string text = out.str();
  EXPECT_NE(text.find("line.belts.0.speed_variation (drawn at random): 0.1 to 0.9\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  max_deviation_m                         1\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  wall_s                          undefined\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  run 10 (line.belts.0.speed_variation=0.9): line one line two\n"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("run 19 "), std::string::npos) << text;  // the 11th failure
  EXPECT_NE(text.find("  and 2 more\n"), std::string::npos) << text;

  SweepTable grid = Grid();
  grid.rows[2] = Failed(2, {"0.1", "true"}, "x");
  grid.rows[6] = Failed(6, {"0.1", "true"}, "x");
  std::ostringstream all_failed;
  PrintSummary(grid, all_failed);
  EXPECT_NE(all_failed.str().find("  0.1       4       4  max_deviation_m  no ok runs\n"),
            std::string::npos)
      << all_failed.str();
}

// Guards the main shipped sweep's chart: belt speed on a numeric x, one
// line per compensation setting, each point the mean, min and max over the
// repeats. compensation=true at 0.05: {1, 3}; at 0.1: {4, 5}.
// compensation=false at 0.1 failed twice: no point there.
TEST(SweepCharts, OneSeriesPerCombinationOfTheOtherParameters) {
  const auto charts = SweepCharts(Grid());
  ASSERT_EQ(charts.size(), 4u);  // 2 metrics (wall_s included) x 2 parameters
  const plots::SweepChart& c = charts[0];
  EXPECT_EQ(c.file, "max_deviation_m_vs_line.belts.0.speed_mps.png");
  EXPECT_EQ(c.x_label, "line.belts.0.speed_mps");
  EXPECT_EQ(c.y_label, "max_deviation_m");
  EXPECT_FALSE(c.categorical_x);
  EXPECT_FALSE(c.scatter);
  ASSERT_EQ(c.series.size(), 2u);
  EXPECT_EQ(c.series[0].label, "control.compensation=true");
  EXPECT_EQ(c.series[0].x, (std::vector<std::string>{"0.05", "0.1"}));
  EXPECT_EQ(c.series[0].mean, (std::vector<double>{2, 4.5}));
  EXPECT_EQ(c.series[0].min, (std::vector<double>{1, 4}));
  EXPECT_EQ(c.series[0].max, (std::vector<double>{3, 5}));
  EXPECT_EQ(c.series[1].label, "control.compensation=false");
  EXPECT_EQ(c.series[1].x, (std::vector<std::string>{"0.05"}));
  EXPECT_EQ(c.series[1].mean, (std::vector<double>{3}));
  // Booleans are categories, in level order, one series per speed.
  const plots::SweepChart& b = charts[1];
  EXPECT_EQ(b.file, "max_deviation_m_vs_control.compensation.png");
  EXPECT_TRUE(b.categorical_x);
  EXPECT_EQ(b.categories, (std::vector<std::string>{"true", "false"}));
  ASSERT_EQ(b.series.size(), 2u);
  EXPECT_EQ(b.series[1].label, "line.belts.0.speed_mps=0.1");
  EXPECT_EQ(b.series[1].x, (std::vector<std::string>{"true"}));
  EXPECT_EQ(charts[2].file, "wall_s_vs_line.belts.0.speed_mps.png");
}

// Guards against unreadable charts: with more than 8 combinations of the
// other parameters, one series pools them. Metric 100 a + 10 b + c over
// b, c in {1, 2, 3}: at a = 1 the mean is 100 + 20 + 2 = 122, the extremes
// 111 and 133. For b the others make 2 x 3 = 6 combinations: 6 series.
TEST(SweepCharts, PoolsWhenThereAreTooManyCombinations) {
  SweepTable t;
  t.parameters = {"a", "b", "c"};
  t.levels = {{"1", "2"}, {"1", "2", "3"}, {"1", "2", "3"}};
  t.metrics = {"m"};
  std::int64_t id = 0;
  for (int a = 1; a <= 2; ++a) {
    for (int b = 1; b <= 3; ++b) {
      for (int c = 1; c <= 3; ++c) {
        t.rows.push_back(Ok(id++, {std::to_string(a), std::to_string(b), std::to_string(c)},
                            {100.0 * a + 10.0 * b + c}));
      }
    }
  }
  const auto charts = SweepCharts(t);
  ASSERT_EQ(charts.size(), 3u);
  ASSERT_EQ(charts[0].series.size(), 1u);
  EXPECT_EQ(charts[0].series[0].label, "all runs (other parameters pooled)");
  EXPECT_EQ(charts[0].series[0].mean[0], 122.0);
  EXPECT_EQ(charts[0].series[0].min[0], 111.0);
  EXPECT_EQ(charts[0].series[0].max[0], 133.0);
  EXPECT_EQ(charts[1].series.size(), 6u);
  EXPECT_EQ(charts[1].series[0].label, "a=1, c=1");
}

// Guards the Monte-Carlo chart: a scatter of the ok runs only, at their own
// values; and a chart with no ok run at all is not made.
TEST(SweepCharts, RandomParameterIsAScatterOfOkRuns) {
  const auto charts = SweepCharts(Random());
  ASSERT_EQ(charts.size(), 2u);
  EXPECT_TRUE(charts[0].scatter);
  EXPECT_FALSE(charts[0].categorical_x);
  ASSERT_EQ(charts[0].series.size(), 1u);
  EXPECT_EQ(charts[0].series[0].x, (std::vector<std::string>{"0.3", "0.1", "0.4", "0.2"}));
  EXPECT_EQ(charts[0].series[0].mean, (std::vector<double>{1.6, 1.2, 1.8, 1.4}));

  SweepTable failed = Random();
  for (Row& r : failed.rows) r = Failed(r.id, r.values, "x");
  EXPECT_TRUE(SweepCharts(failed).empty());
}

// Monte-Carlo draws crossed with listed values: one colour per listed
// value, so compensation on and off are told apart in the scatter.
TEST(SweepCharts, ScatterSplitsByTheListedParameters) {
  SweepTable t;
  t.name = "mc";
  t.parameters = {"line.belts.0.speed_mps", "control.compensation"};
  t.levels = {{}, {"true", "false"}};
  t.metrics = {"max_deviation_m"};
  t.grid = false;
  t.rows = {Ok(0, {"0.1", "true"}, {0.01}), Ok(1, {"0.2", "true"}, {0.02}),
            Ok(2, {"0.1", "false"}, {0.1}), Ok(3, {"0.2", "false"}, {0.2})};
  const auto charts = SweepCharts(t);
  ASSERT_EQ(charts.size(), 2u);  // against each parameter
  ASSERT_TRUE(charts[0].scatter);
  ASSERT_EQ(charts[0].series.size(), 2u);
  EXPECT_EQ(charts[0].series[0].label, "control.compensation=true");
  EXPECT_EQ(charts[0].series[0].mean, (std::vector<double>{0.01, 0.02}));
  EXPECT_EQ(charts[0].series[1].label, "control.compensation=false");
  EXPECT_EQ(charts[0].series[1].x, (std::vector<std::string>{"0.1", "0.2"}));
}

// Guards file names made from parameter paths: only [A-Za-z0-9._-], and two
// paths that map to the same name do not overwrite each other's chart.
TEST(SweepCharts, FileNamesAreSafeAndDistinct) {
  SweepTable t;
  t.parameters = {"units.a b/c", "units.a_b_c"};
  t.levels = {{"1", "2"}, {"1"}};
  t.metrics = {"m"};
  t.rows = {Ok(0, {"1", "1"}, {1}), Ok(1, {"2", "1"}, {2})};
  const auto charts = SweepCharts(t);
  ASSERT_EQ(charts.size(), 2u);
  EXPECT_EQ(charts[0].file, "m_vs_units.a_b_c.png");
  EXPECT_EQ(charts[1].file, "m_vs_units.a_b_c_2.png");
}

class WriteSweepReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("linesim sweep report 'test' " + std::to_string(getpid()) + " " + info->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string ReadAll(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  fs::path dir_;
};

// Guards the whole report: summary.json (no temporary file left) lists the
// plots it was written with, and each is a PNG (signature from the PNG
// specification, section 5.2).
TEST_F(WriteSweepReportTest, WritesSummaryAndPlots) {
  const auto files = WriteSweepReport(dir_.string(), Grid());
  ASSERT_EQ(files.size(), 5u);
  EXPECT_EQ(files[0], (dir_ / "summary.json").string());
  const auto summary = nlohmann::json::parse(ReadAll(dir_ / "summary.json"));
  EXPECT_EQ(summary["runs"], 8);
  ASSERT_EQ(summary["plots"]["files"].size(), 4u);
  EXPECT_EQ(summary["plots"]["files"][0], "max_deviation_m_vs_line.belts.0.speed_mps.png");
  for (std::size_t i = 1; i < files.size(); ++i) {
    EXPECT_EQ(ReadAll(files[i]).substr(0, 8), "\x89PNG\r\n\x1a\n") << files[i];
  }
  EXPECT_FALSE(fs::exists(dir_ / "summary.json.tmp"));
}

// Guards the numbers against a plotting problem: without gnuplot the
// summary is still written, with the error in place of the plot list.
TEST_F(WriteSweepReportTest, PlotFailureKeepsTheSummary) {
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", (dir_ / "nowhere").c_str(), 1);
  std::vector<std::string> files;
  EXPECT_NO_THROW(files = WriteSweepReport(dir_.string(), Grid()));
  setenv("PATH", path.c_str(), 1);
  EXPECT_EQ(files, (std::vector<std::string>{(dir_ / "summary.json").string()}));
  const auto summary = nlohmann::json::parse(ReadAll(dir_ / "summary.json"));
  EXPECT_EQ(summary["failed"], 2);
  EXPECT_FALSE(summary["plots"].contains("files"));
  EXPECT_NE(summary["plots"]["error"].get<std::string>().find("cannot run gnuplot"),
            std::string::npos)
      << summary["plots"];
}

// Five repeats of one scenario (no parameters) with a reference, as paper 2's
// Table 1: signed errors -2, -1, 0, 1, 2 (mean 0, sample std sqrt(10/4),
// max |x| 2, mean |x| 6/5); run 5 failed and does not count.
SweepTable Repeats() {
  SweepTable t;
  t.name = "van_entry";
  t.metrics = {"error_x_m", "wall_s"};
  for (int i = 0; i < 5; ++i) t.rows.push_back(Ok(i, {}, {i - 2.0, 1.0}));
  t.rows.push_back(Failed(5, {}, "follower: did not reach the route's end", {NAN, 1.0}));
  t.reference = {"paper 2, Table 1",
                 {{"error_x_m", "X (m)", 0.019, 0.005, 0.004, "the scanner's noise"}},
                 "table1"};
  return t;
}

// Guards the repeatability report: summary.json's overall statistics and
// the reference beside ours.
TEST(Summarize, RepeatsWithoutParametersAndAReference) {
  const auto s = Summarize(Repeats());
  EXPECT_EQ(s["ok"], 5);
  const auto& x = s["overall"]["error_x_m"];
  EXPECT_EQ(x["n"], 5);
  EXPECT_DOUBLE_EQ(x["std"].get<double>(), std::sqrt(10.0 / 4.0));
  EXPECT_EQ(x["max_abs"], 2.0);
  EXPECT_DOUBLE_EQ(x["mean_abs"].get<double>(), 1.2);
  const auto& ref = s["reference"]["metrics"]["error_x_m"];
  EXPECT_EQ(s["reference"]["title"], "paper 2, Table 1");
  EXPECT_EQ(ref["label"], "X (m)");
  EXPECT_EQ(ref["ours"]["max_abs"], 2.0);
  EXPECT_EQ(ref["reference"]["max_abs"], 0.019);
  EXPECT_EQ(ref["reference"]["mean_abs"], 0.004);
}

// Guards the terminal table: each figure's row with ours | the reference's.
TEST(PrintSummary, RepeatsPrintOverallAndTheReferenceTable) {
  std::ostringstream out;
  PrintSummary(Repeats(), out);
  const std::string text = out.str();
  EXPECT_NE(text.find("over all runs:"), std::string::npos) << text;
  EXPECT_NE(text.find("paper 2, Table 1 (this sweep | reference):"), std::string::npos) << text;
  EXPECT_NE(text.find("maximum absolute error      2 | 0.019"), std::string::npos) << text;
  EXPECT_NE(text.find("mean absolute error       1.2 | 0.004"), std::string::npos) << text;
  EXPECT_NE(text.find("run 5 (seed 105): follower"), std::string::npos) << text;
}

// Guards the histograms: one per metric but wall_s, of the ok runs only,
// with the reference's figures and label on it.
TEST(SweepCharts, RepeatsGiveOneHistogramPerMetric) {
  const auto charts = SweepCharts(Repeats());
  ASSERT_EQ(charts.size(), 1u);
  EXPECT_TRUE(charts[0].histogram);
  EXPECT_EQ(charts[0].file, "error_x_m_histogram.png");
  EXPECT_EQ(charts[0].series[0].mean, (std::vector<double>{-2, -1, 0, 1, 2}));
  EXPECT_EQ(charts[0].reference.label, "paper 2, Table 1");
  EXPECT_EQ(charts[0].reference.max_abs, 0.019);
  EXPECT_EQ(charts[0].reference.std, 0.005);
  EXPECT_EQ(charts[0].x_label, "X (m)");
}

// Guards against a histogram of a metric that is the same in every run
// (its axes would span +-1e-12): no chart, and the terminal names it.
TEST(SweepCharts, AConstantMetricGetsNoHistogram) {
  SweepTable t = Repeats();
  t.metrics = {"error_x_m", "collisions", "wall_s"};
  for (auto& row : t.rows) row.metrics.insert(row.metrics.begin() + 1, 0.0);
  const auto charts = SweepCharts(t);
  ASSERT_EQ(charts.size(), 1u);
  EXPECT_EQ(charts[0].file, "error_x_m_histogram.png");
  std::ostringstream out;
  PrintSummary(t, out);
  EXPECT_NE(out.str().find("the same in every run (no histogram): collisions"), std::string::npos)
      << out.str();
}

// Guards that gnuplot draws the histogram with its normal curve, the
// reference's maxima as lines and its std as a curve, beside the
// reference's table files.
TEST_F(WriteSweepReportTest, WritesHistograms) {
  const auto files = WriteSweepReport(dir_.string(), Repeats());
  ASSERT_EQ(files.size(), 4u);
  EXPECT_EQ(fs::path(files[1]).filename(), "table1.csv");
  EXPECT_EQ(fs::path(files[2]).filename(), "table1.md");
  EXPECT_EQ(ReadAll(files[3]).substr(0, 8), "\x89PNG\r\n\x1a\n");
  const std::string script = ReadAll(dir_ / "sweep_plots.gp");
  EXPECT_NE(script.find("exp(-0.5 *"), std::string::npos);
  EXPECT_NE(script.find("set arrow from -0.019, graph 0 to -0.019, graph 1"), std::string::npos)
      << script;
  EXPECT_NE(script.find("title 'source: paper 2, Table 1'"), std::string::npos) << script;
  EXPECT_NE(script.find("source: std 0.005 m, as N(0, std)"), std::string::npos) << script;
}

// Guards Table 1 as files: ours (the 5 ok runs -2..2: max |x| 2, std
// sqrt(10 / 4), mean |x| 6 / 5) beside the reference's, each figure a row
// of the CSV; the Markdown in the source's layout with the metric's note.
TEST_F(WriteSweepReportTest, WritesTheReferenceTable) {
  const auto files = WriteReferenceTable(dir_.string(), Repeats());
  ASSERT_EQ(files.size(), 2u);
  const std::string csv = ReadAll(dir_ / "table1.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "metric,label,figure,ours,reference");
  EXPECT_NE(csv.find("error_x_m,X (m),max_abs,2,0.019\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("error_x_m,X (m),mean_abs,1.2,0.004\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("error_x_m,X (m),std," + cosim::FormatValue(std::sqrt(2.5)) + ",0.005\n"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find("error_x_m,X (m),runs,5,\n"), std::string::npos) << csv;
  const std::string md = ReadAll(dir_ / "table1.md");
  EXPECT_NE(md.find("| maximum absolute error | 2 | 0.019 |"), std::string::npos) << md;
  EXPECT_NE(md.find("- X (m): the scanner's noise"), std::string::npos) << md;
  SweepTable none = Repeats();
  none.reference = {};
  EXPECT_TRUE(WriteReferenceTable(dir_.string(), none).empty());
}

}  // namespace
}  // namespace linesim::sweep
