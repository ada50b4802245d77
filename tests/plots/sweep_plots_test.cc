#include "plots/sweep_plots.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "plots/gnuplot.h"

namespace linesim::plots {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, with a space and a quote in its name so that any
// quoting mistake in running gnuplot shows; removed afterwards.
class SweepPlotsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("linesim sweep plots 'test' " + std::to_string(getpid()) + " " + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string ReadAll(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  // The 8-byte signature every PNG file starts with (PNG specification,
  // section 5.2).
  static bool IsPng(const fs::path& file) {
    const std::string bytes = ReadAll(file);
    return bytes.size() > 8 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
  }

  // Belt speed on x, deviation on y, one line per compensation setting: the
  // shape of the main shipped sweep. Levels given out of order on purpose.
  static SweepChart NumericChart() {
    SweepChart chart;
    chart.file = "max_deviation_m_vs_line.belts.0.speed_mps.png";
    chart.title = "crossing 'test': max_deviation_m against line.belts.0.speed_mps";
    chart.x_label = "line.belts.0.speed_mps";
    chart.y_label = "max_deviation_m";
    chart.series = {
        {"control.compensation=true",
         {"0.25", "0.05", "0.15"},
         {3, 1, 2},
         {2.5, 0.5, 1.5},
         {3.5, 1.5, 2.5}},
        {"control.compensation=false", {"0.05", "0.15", "0.25"}, {2, 4, 6}, {1, 3, 5}, {3, 5, 7}}};
    return chart;
  }

  static SweepChart CategoricalChart() {
    SweepChart chart;
    chart.file = "wall_s_vs_master.algorithm.png";
    chart.title = "wall_s against master.algorithm";
    chart.x_label = "master.algorithm";
    chart.y_label = "wall_s";
    chart.categorical_x = true;
    chart.categories = {"jacobi", "gauss_seidel"};
    chart.series = {{"", {"gauss_seidel", "jacobi"}, {1.0, 2.0}, {0.9, 1.8}, {1.1, 2.2}}};
    return chart;
  }

  static SweepChart ScatterChart() {
    SweepChart chart;
    chart.file = "max_deviation_m_vs_line.belts.0.speed_variation.png";
    chart.x_label = "line.belts.0.speed_variation";
    chart.y_label = "max_deviation_m";
    chart.scatter = true;
    chart.series = {{"", {"0.01", "0.05", "0.02", "0.1"}, {0.1, 0.5, 0.2, 1.0}, {}, {}}};
    return chart;
  }

  // A `gnuplot` on a PATH of its own that prints `message` and exits with 1.
  void InstallFailingGnuplot(const std::string& message) const {
    const fs::path bin = dir_ / "bin";
    fs::create_directories(bin);
    std::ofstream(bin / "gnuplot") << "#!/bin/sh\necho '" << message << "' >&2\nexit 1\n";
    fs::permissions(bin / "gnuplot", fs::perms::owner_all);
    setenv("PATH", bin.c_str(), 1);
  }

  fs::path dir_;
};

// Restores PATH when a test that changed it ends, whatever way it ends.
class PathGuard {
 public:
  PathGuard() : path_(std::getenv("PATH") ? std::getenv("PATH") : "") {}
  ~PathGuard() { setenv("PATH", path_.c_str(), 1); }

 private:
  std::string path_;
};

// Guards against a sweep that silently produces no plots or broken files:
// numeric, categorical and scatter charts each give a real PNG, under the
// file name asked for, in the order given.
TEST_F(SweepPlotsTest, WritesOnePngPerChart) {
  const auto files =
      WriteSweepPlots(dir_.string(), {NumericChart(), CategoricalChart(), ScatterChart()});
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(fs::path(files[0]).filename(), NumericChart().file);
  EXPECT_EQ(fs::path(files[1]).filename(), CategoricalChart().file);
  EXPECT_EQ(fs::path(files[2]).filename(), ScatterChart().file);
  for (const auto& f : files) EXPECT_TRUE(IsPng(f)) << f;
}

// Guards the drawing of each kind: a numeric line joins its points in x
// order (levels may come in any order) with min-max bars; categories sit at
// 0..n-1 in the chart's category order, labelled with their text; a
// scatter has one point per run.
TEST_F(SweepPlotsTest, ScriptDrawsEachKindAsDocumented) {
  WriteSweepPlots(dir_.string(), {NumericChart(), CategoricalChart(), ScatterChart()});
  const std::string script = ReadAll(dir_ / "sweep_plots.gp");
  // x mean min max per line; the first series sorted from 0.05 to 0.25.
  EXPECT_NE(script.find("$chart0_0 << EOD\n0.05,1,0.5,1.5\n0.15,2,1.5,2.5\n0.25,3,2.5,3.5\nEOD\n"),
            std::string::npos)
      << script;
  EXPECT_NE(script.find("with yerrorlines"), std::string::npos);
  EXPECT_NE(script.find("title 'control.compensation=false'"), std::string::npos);
  // jacobi first as the chart's categories say, though the series lists
  // gauss_seidel first.
  EXPECT_NE(script.find("set xtics ('jacobi' 0, 'gauss_seidel' 1)"), std::string::npos) << script;
  EXPECT_NE(script.find("$chart1_0 << EOD\n1,1,0.9,1.1\n0,2,1.8,2.2\nEOD\n"), std::string::npos)
      << script;
  EXPECT_NE(script.find("with yerrorbars"), std::string::npos);
  EXPECT_NE(script.find("$chart2_0 << EOD\n0.01,0.1\n0.02,0.2\n0.05,0.5\n0.1,1\nEOD\n"),
            std::string::npos)
      << script;
  EXPECT_NE(script.find("with points"), std::string::npos);
  // Quotes in titles are doubled, not left to end the string.
  EXPECT_NE(script.find("'crossing ''test'': max_deviation_m"), std::string::npos);
}

// Guards against a script that only works where it was written: run again
// in its folder, it redraws every PNG from its inline data.
TEST_F(SweepPlotsTest, ScriptRedrawsThePlotsOnItsOwn) {
  const auto files = WriteSweepPlots(dir_.string(), {NumericChart(), ScatterChart()});
  const std::string first = ReadAll(files[0]);
  for (const auto& f : files) fs::remove(f);
  const GnuplotResult run = RunGnuplot(dir_.string(), "sweep_plots.gp");
  EXPECT_EQ(run.exit_status, 0) << run.errors;
  for (const auto& f : files) EXPECT_TRUE(IsPng(f)) << f;
  EXPECT_EQ(ReadAll(files[0]), first);
}

// Guards against NaN reaching gnuplot (it would stop a line or fail the
// autoscale): non-finite points are left out, and a chart left with
// nothing is not drawn at all.
TEST_F(SweepPlotsTest, NonFinitePointsAreLeftOut) {
  SweepChart partly = NumericChart();
  partly.series[0].mean[1] = NAN;
  partly.series[1].max[0] = INFINITY;
  SweepChart nothing = ScatterChart();
  nothing.series[0].mean.assign(4, NAN);
  const auto files = WriteSweepPlots(dir_.string(), {partly, nothing});
  ASSERT_EQ(files.size(), 1u);
  EXPECT_TRUE(IsPng(files[0]));
  EXPECT_FALSE(fs::exists(dir_ / nothing.file));
  const std::string script = ReadAll(dir_ / "sweep_plots.gp");
  EXPECT_EQ(script.find("nan"), std::string::npos) << script;
  EXPECT_EQ(script.find("inf"), std::string::npos) << script;
}

// Guards file names: anything outside [A-Za-z0-9._-] (path separators,
// spaces, quotes) becomes '_', so a parameter path can never write outside
// the folder or break the script's quoting.
TEST_F(SweepPlotsTest, SafeFileNameKeepsOnlyPortableCharacters) {
  EXPECT_EQ(SafeFileName("max_deviation_m_vs_line.belts.0.speed_mps.png"),
            "max_deviation_m_vs_line.belts.0.speed_mps.png");
  EXPECT_EQ(SafeFileName("a/b c'd\"e:f.png"), "a_b_c_d_e_f.png");
}

// Guards against charts drawn wrong instead of refused: an unsafe or
// repeated file name, text on a numeric axis and series of unequal length
// are errors that name the chart's file, and nothing is drawn.
TEST_F(SweepPlotsTest, BadChartsAreRefusedByFileName) {
  const auto refused = [&](const std::vector<SweepChart>& charts, const std::string& expected) {
    try {
      WriteSweepPlots(dir_.string(), charts);
      ADD_FAILURE() << "accepted a chart that should be refused for: " << expected;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  SweepChart unsafe = NumericChart();
  unsafe.file = "../escape.png";
  refused({unsafe}, "'../escape.png': the file name must be made of");
  refused({NumericChart(), NumericChart()}, "two charts have this file name");
  SweepChart text = NumericChart();
  text.series[1].x[2] = "fast";
  refused({text}, "x value 'fast' is not a number");
  SweepChart ragged = CategoricalChart();
  ragged.series[0].max.pop_back();
  refused({ragged},
          "'wall_s_vs_master.algorithm.png': series '' has 2 x values but 2 means, "
          "2 minima and 1 maxima");
  EXPECT_FALSE(fs::exists(dir_ / "sweep_plots.gp"));
}

// Guards against gnuplot's absence or its errors being swallowed: both are
// errors, the second with gnuplot's own text and the script's path.
TEST_F(SweepPlotsTest, GnuplotMissingOrFailingIsAClearError) {
  PathGuard keep_path;
  setenv("PATH", (dir_ / "nowhere").c_str(), 1);
  try {
    WriteSweepPlots(dir_.string(), {NumericChart()});
    ADD_FAILURE() << "gnuplot ran without a PATH to it";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot run gnuplot"), std::string::npos) << e.what();
  }
  InstallFailingGnuplot("line 7: undefined variable: boom");
  try {
    WriteSweepPlots(dir_.string(), {NumericChart()});
    ADD_FAILURE() << "gnuplot's failure was not reported";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("gnuplot failed on " + (dir_ / "sweep_plots.gp").string() +
                        " (exit status 1): line 7: undefined variable: boom"),
              std::string::npos)
        << what;
  }
}

// Guards the histogram of `run --runs` as paper 2's Figs. 6-11 with Table
// 1 beside it: captioned with what the metric measures (not its name), in
// mm (the errors are millimetres), the runs' mean drawn (not only cited),
// the source's largest error and std in the bounds' black.
TEST_F(SweepPlotsTest, HistogramIsCaptionedInMillimetresWithItsMeanDrawn) {
  SweepChart chart;
  chart.file = "beacon_error_x_m_histogram.png";
  chart.histogram = true;
  chart.metric = "beacon_error_x_m";
  chart.run_caption = "van_entry";
  chart.reference = {"paper 2, Table 1", 0.019, 0.005, 0.004};
  chart.series = {{"", {}, {-0.002, -0.001, 0.0, 0.001, 0.002, 0.003, 0.004}, {}, {}}};
  WriteSweepPlots(dir_.string(), {chart});
  const std::string script = ReadAll(dir_ / "sweep_plots.gp");
  EXPECT_NE(
      script.find("set title 'Final pose error in X by the beacons: distribution over 7 runs' . "
                  "\"\\n\" . 'van_entry'"),
      std::string::npos)
      << script;
  EXPECT_NE(script.find("set xlabel 'final pose error in X by the beacons (mm)'"),
            std::string::npos)
      << script;
  EXPECT_EQ(script.find("beacon_error_x_m'"), std::string::npos) << script;
  // Samples and figures in mm; the mean (0) drawn as a line.
  EXPECT_NE(script.find("set arrow from -19, graph 0 to -19, graph 1 nohead dt 2 lw 2 lc rgb "
                        "'#000000'"),
            std::string::npos)
      << script;
  EXPECT_NE(script.find("graph 1 nohead lw 2 dt 4 lc rgb '#D55E00'"), std::string::npos) << script;
  EXPECT_NE(script.find("title 'mean of the runs: 1 mm'"), std::string::npos) << script;
  EXPECT_NE(script.find("title 'source: std 5 mm, as N(0, std)'"), std::string::npos) << script;
  EXPECT_NE(script.find("title 'source: paper 2, Table 1'"), std::string::npos) << script;
}

// Guards against a script or gnuplot run for nothing: no charts, no files.
TEST_F(SweepPlotsTest, NoChartsWriteNothing) {
  EXPECT_TRUE(WriteSweepPlots(dir_.string(), {}).empty());
  EXPECT_FALSE(fs::exists(dir_ / "sweep_plots.gp"));
}

}  // namespace
}  // namespace linesim::plots
