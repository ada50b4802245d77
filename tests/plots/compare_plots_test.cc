#include "plots/compare_plots.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

namespace linesim::plots {
namespace {

namespace fs = std::filesystem;

class ComparePlotsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("linesim compare 'test' " + std::to_string(getpid()) + " " + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "nominal");
    fs::create_directories(dir_ / "modified");
    // Two runs whose columns sit in different places (the nominal run
    // records no estimator): each is found by name in its own file.
    std::ofstream a(dir_ / "nominal" / "signals.csv");
    a << "time,belt.on[0],deviation.deviation\n";
    std::ofstream b(dir_ / "modified" / "signals.csv");
    b << "time,surface_estimator.x,deviation.deviation,belt.on[0]\n";
    for (int i = 0; i <= 200; ++i) {
      const double t = 0.1 * i;
      a << t << "," << (t >= 5 ? 1 : 0) << "," << 0.01 * t << "\n";
      b << t << ",0," << 0.001 * t << "," << (t >= 5 ? 1 : 0) << "\n";
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  ComparisonPlotSpec Spec() const {
    ComparisonPlotSpec spec;
    spec.run_caption = "nominal 'against' modified";
    spec.runs = {{"nominal/signals.csv", "deviation.deviation", "nominal"},
                 {"modified/signals.csv", "deviation.deviation", "modified"}};
    spec.belt_on_columns = {"belt.on[0]"};
    spec.bound_m = 0.04;
    spec.bound_label = "4 cm (paper 1, Sec. VI-B)";
    return spec;
  }

  static std::string ReadAll(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  fs::path dir_;
};

// Guards paper 1 Fig. 6 as one figure: both runs' curves from their own
// files (column 3 in each here), the line's on state from the first run
// (its column 2), the bound, the runs' labels in a legend below the data.
TEST_F(ComparePlotsTest, OverlaysEveryRunWithTheLineStateAndTheBound) {
  const std::string s = ComparisonScript(dir_.string(), Spec());
  EXPECT_NE(
      s.find("'nominal/signals.csv' skip 1 using 1:((column(2) > 0.5) ? 0.97 : 1):(1) axes x1y2"),
      std::string::npos)
      << s;
  // Each run in mm, the bound at 40 mm in the bounds' style (black dashed,
  // as error.png draws it).
  EXPECT_NE(s.find("'nominal/signals.csv' skip 1 using 1:(1000 * column(3)) with lines"),
            std::string::npos)
      << s;
  EXPECT_NE(s.find("'modified/signals.csv' skip 1 using 1:(1000 * column(3)) with lines"),
            std::string::npos)
      << s;
  EXPECT_NE(s.find("title 'nominal'"), std::string::npos);
  EXPECT_NE(s.find("title 'modified'"), std::string::npos);
  EXPECT_NE(s.find("40 with lines dt 2 lw 2 lc rgb '#000000' title '4 cm (paper 1, Sec. VI-B)'"),
            std::string::npos)
      << s;
  EXPECT_NE(s.find("set ylabel 'deviation from the path (mm)'"), std::string::npos) << s;
  EXPECT_NE(s.find("title 'line on (band along the top)'"), std::string::npos);
  EXPECT_NE(s.find("set key at screen 0.5, 0.01 center bottom"), std::string::npos);
  const std::string png = WriteComparisonPlot(dir_.string(), Spec());
  EXPECT_EQ(fs::path(png).filename(), "comparison.png");
  EXPECT_EQ(ReadAll(png).substr(0, 8), "\x89PNG\r\n\x1a\n");
  EXPECT_TRUE(fs::exists(dir_ / "comparison.gp"));
}

TEST_F(ComparePlotsTest, SvgAndAMissingColumnIsNamed) {
  ComparisonPlotSpec spec = Spec();
  spec.format = PlotFormat::kSvg;
  const std::string svg = ReadAll(WriteComparisonPlot(dir_.string(), spec));
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("nominal"), std::string::npos);
  spec.runs[1].error_column = "deviation.deviatoin";
  try {
    ComparisonScript(dir_.string(), spec);
    FAIL() << "an unknown column was accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("modified/signals.csv: no column 'deviation.deviatoin'"), std::string::npos)
        << what;
    EXPECT_NE(what.find("deviation.deviation"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace linesim::plots
