#include "figure_layout.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include "plots/compare_plots.h"
#include "plots/robot_plots.h"
#include "plots/sweep_plots.h"

namespace linesim::plots {
namespace {

namespace fs = std::filesystem;

// Every figure type drawn from synthetic runs shaped as the shipped
// scenarios' (a fleet on the line with workers, a scan, a climb, the
// safety fields, four PX4Flow; a comparison; a sweep's charts and a
// histogram with a source's figures), checked by gnuplot's own layout:
// no text overlaps another, none leaves the canvas, no legend entry lies
// in a plot area (tests/plots/figure_layout.h says how).
class FigureLayoutTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("linesim layout " + std::to_string(getpid()) + " " + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Checks every figure the script draws; returns how many there were.
  std::size_t ExpectClean(const std::string& script) const {
    const auto figures = layout::DrawAndRead(dir_.string(), script);
    for (const auto& f : figures) {
      EXPECT_FALSE(f.texts.empty()) << f.file;
      EXPECT_FALSE(f.plot_areas.empty()) << f.file;
      for (const auto& problem : layout::Problems(f)) ADD_FAILURE() << f.file << ": " << problem;
    }
    return figures.size();
  }

  fs::path dir_;
};

constexpr double kPi = std::numbers::pi;
constexpr int kBeams = 541;

// 40 s of a Rob@Work 3 crossing the line (stopped by its safety fields
// from 8 to 15 s for a worker), another holding on the line, a Husky
// driving along it, two workers, four PX4Flow, a laser's ranges, a climb
// over a ramp.
void WriteFleetRun(const fs::path& file) {
  std::ofstream out(file);
  out << "time,x,y,yaw,z";
  for (int w = 0; w < 4; ++w) out << ",wx[" << w << "],wy[" << w << "]";
  out << ",deviation,done,belt.speed,belt.on,belt.travel";
  for (const char* kind : {"raw", "truth", "filtered"}) {
    for (int k = 0; k < 4; ++k) out << "," << kind << "[" << k << "]";
  }
  out << ",reference,vx,vy,cap,protective,warning,distance,field_set";
  out << ",b.x,b.y,b.yaw,h.x,h.y,h.yaw";
  for (int k = 1; k <= 2; ++k) {
    out << ",worker_" << k << ".x,worker_" << k << ".y";
    for (int j = 0; j < 4; ++j) out << ",worker_" << k << ".legs[" << j << "]";
  }
  out << ",scan_time";
  for (int k = 0; k < kBeams; ++k) out << ",ranges[" << k << "]";
  out << "\n";
  double y = -3.5;
  for (int i = 0; i <= 400; ++i) {
    const double t = 0.1 * i;
    const bool stopped = t >= 8.0 && t < 15.0;
    const double v = stopped ? 0.0 : 0.2;
    if (i > 0) y = std::min(2.5, y + 0.1 * v);
    const double x = -0.5 + 0.002 * std::sin(t), yaw = 0.5 * kPi;
    const double z = std::clamp((y + 1.0) * 0.27, 0.0, 0.54) + 0.1;
    out << t << "," << x << "," << y << "," << yaw << "," << z;
    const double wx[4] = {0.368, -0.368, -0.368, 0.368}, wy[4] = {0.186, 0.134, -0.186, -0.134};
    for (int w = 0; w < 4; ++w) out << "," << x - wy[w] << "," << y + wx[w];
    const bool on = t >= 2.0;
    out << "," << 0.004 * std::abs(std::sin(t)) << "," << (t >= 30 ? 1 : 0) << ","
        << (on ? 0.1 : 0.0) << "," << (on ? 1 : 0) << "," << (on ? 0.1 * (t - 2.0) : 0.0);
    for (int k = 0; k < 4; ++k) out << "," << (on ? 0.1 : 0.0) + 0.01 * std::sin(7 * t + k);
    for (int k = 0; k < 4; ++k) out << "," << (on ? 0.1 : 0.0);
    for (int k = 0; k < 4; ++k) out << "," << (on ? 0.1 * (1 - std::exp(-(t - 2))) : 0.0);
    const double worker_x = t < 8 ? -3.5 + 0.4 * t : -0.3;
    const double distance = std::hypot(worker_x - x, -1.2 - y) - 0.3;
    out << "," << (on ? 0.1 : 0.0) << ",0," << v << "," << (stopped ? 0.0 : -1.0) << ","
        << (stopped ? 0 : 1) << "," << (t >= 6 && t < 15 ? 0 : 1) << "," << std::max(0.1, distance)
        << "," << (stopped ? 0 : 1);
    out << ",1.5,0,0," << -9.0 + 0.45 * t << ",-5,0";
    out << "," << worker_x << ",-1.2," << worker_x - 0.1 << ",-1.1," << worker_x + 0.1 << ",-1.3";
    const double w2 = std::min(-1.4, -6.5 + 0.3 * t);
    out << ",1.5," << w2 << ",1.4," << w2 << ",1.6," << w2;
    out << "," << std::floor(t / 0.04) * 0.04;
    for (int k = 0; k < kBeams; ++k) out << "," << 4.0 + std::sin(0.05 * k);
    out << "\n";
  }
}

RobotPlotSpec FleetSpec() {
  RobotPlotSpec spec;
  spec.run_caption = "two Rob@Work 3 and a Husky on one running line (fleet_test, seed 1)";
  spec.robot_name = "raw3_a";
  models::Belt belt;
  belt.name = "line";
  belt.area = {0.0, 0.0, 20.0, 2.0, 0.0};
  spec.scene.belts = {belt};
  models::Obstacle pillar{"pillar", "pillar", {}};
  pillar.solid.kind = models::Solid::Kind::kCylinder;
  pillar.solid.x_m = -6.0;
  pillar.solid.y_m = -7.5;
  pillar.solid.radius_m = 0.25;
  spec.scene.obstacles = {pillar};
  models::CarriedObject body{"body", 0, {}};
  body.solid.x_m = -6.0;
  body.solid.length_m = 4.5;
  body.solid.width_m = 1.8;
  spec.scene.carried = {body};
  models::TerrainPiece ramp;
  ramp.name = "ramp";
  ramp.pitch_rad = std::atan2(0.54, 2.0);
  ramp.yaw_rad = 0.5 * kPi;
  ramp.length_m = std::hypot(2.0, 0.54);
  ramp.width_m = 1.2;
  ramp.center_x_m = -0.5;
  ramp.center_y_m = 0.0;
  ramp.center_z_m = 0.27;
  spec.scene.terrain = {ramp};
  spec.belt_travel_columns = {"belt.travel"};
  spec.path_m = {{-0.5, -3.5}, {-0.5, 2.5}};
  spec.x_column = "x";
  spec.y_column = "y";
  spec.yaw_column = "yaw";
  spec.z_column = "z";
  for (int w = 0; w < 4; ++w) {
    spec.wheel_columns.emplace_back("wx[" + std::to_string(w) + "]",
                                    "wy[" + std::to_string(w) + "]");
  }
  spec.error_column = "deviation";
  spec.error_label = "deviation from the path";
  spec.error_name = "deviation of the robot's centre from the desired path";
  spec.error_bound = {0.04, "paper 1: under 4 cm with the modified system (Sec. VI-B)", ""};
  spec.belt_speed_columns = {"belt.speed"};
  spec.belt_on_columns = {"belt.on"};
  for (int k = 0; k < 4; ++k) {
    const std::string i = "[" + std::to_string(k) + "]";
    spec.flow_columns.push_back("raw" + i);
    spec.flow_truth_columns.push_back("truth" + i);
    spec.flow_filtered_columns.push_back("filtered" + i);
  }
  spec.flow_labels = {"flow_front_left", "flow_rear_left", "flow_rear_right", "flow_front_right"};
  spec.flow_reference_column = "reference";
  spec.scan.sensor = "raw3_a.laser_front";
  spec.scan.time_s = 14.0;
  spec.scan.mount_x_m = 0.4;
  spec.scan.first_beam_rad = -0.75 * kPi;
  spec.scan.beam_step_rad = 1.5 * kPi / (kBeams - 1);
  spec.scan.no_return_m = 29.0;
  for (int k = 0; k < kBeams; ++k) {
    spec.scan.range_columns.push_back("ranges[" + std::to_string(k) + "]");
  }
  spec.scan.scan_time_column = "scan_time";
  spec.safety = {"vx",      "vy",       "cap",       "protective",
                 "warning", "distance", "field_set", {{0.15, 0.65}, {0.25, 0.75}, {1.0, 1.5}}};
  for (int k = 1; k <= 2; ++k) {
    RobotPlotSpec::Worker w;
    w.name = "worker_" + std::to_string(k);
    w.x_column = w.name + ".x";
    w.y_column = w.name + ".y";
    for (int j = 0; j < 4; ++j) w.leg_columns[j] = w.name + ".legs[" + std::to_string(j) + "]";
    w.leg_radius_m = 0.045;
    w.torso_radius_m = 0.2;
    spec.workers.push_back(w);
  }
  spec.others = {{"raw3_b", "b.x", "b.y", "b.yaw", 1.03, 0.57, 1},
                 {"husky", "h.x", "h.y", "h.yaw", 0.99, 0.67, 2}};
  return spec;
}

// Guards every robot figure's layout (the fleet and worker top views'
// labels, the scan with robots and workers, the side view's legend, the
// safety panels, Fig. 4's panels, the error and belt plots), in PNG's
// layout and in SVG's.
TEST_F(FigureLayoutTest, RobotFiguresHaveNoOverlapsAndLegendsOutsideTheData) {
  WriteFleetRun(dir_ / "signals.csv");
  const auto files = WriteRobotPlots(dir_.string(), FleetSpec());
  ASSERT_EQ(files.size(), 7u);
  EXPECT_EQ(ExpectClean("plots.gp"), 7u);
  // The robots and workers the scan met are drawn and named.
  std::ifstream in(dir_ / "plots.gp");
  const std::string script{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  for (const char* name : {"title 'raw3_b'", "title 'husky'", "title 'worker_1 (torso, legs)'",
                           "title 'worker_1: walk'", "title 'worker_2: walk'"}) {
    EXPECT_NE(script.find(name), std::string::npos) << name;
  }
}

// Guards the same robot standing still the whole run (a hold): its time
// labels join into one and the view stays clean.
TEST_F(FigureLayoutTest, AStandingRobotsLabelsStayApart) {
  WriteFleetRun(dir_ / "signals.csv");
  RobotPlotSpec spec = FleetSpec();
  spec.x_column = "b.x";
  spec.y_column = "b.y";
  spec.yaw_column = "b.yaw";
  spec.others = {};
  spec.path_m = {{1.5, 0.0}};
  spec.z_column.clear();
  spec.scan = {};
  spec.footprint_count = 9;
  WriteRobotPlots(dir_.string(), spec);
  EXPECT_GE(ExpectClean("plots.gp"), 5u);
}

// Guards paper 1 Fig. 6 as the comparison draws it.
TEST_F(FigureLayoutTest, ComparisonHasNoOverlaps) {
  fs::create_directories(dir_ / "nominal");
  fs::create_directories(dir_ / "modified");
  WriteFleetRun(dir_ / "nominal" / "signals.csv");
  WriteFleetRun(dir_ / "modified" / "signals.csv");
  ComparisonPlotSpec spec;
  spec.run_caption = "paper 1 Fig. 6, cross_line at 0.10 m/s, nominal against modified";
  spec.runs = {{"nominal/signals.csv", "deviation", "nominal (no surface knowledge)"},
               {"modified/signals.csv", "deviation", "modified (Algorithm 1)"}};
  spec.belt_on_columns = {"belt.on"};
  spec.bound_m = 0.04;
  spec.bound_label = "paper 1: under 4 cm with the modified system (Sec. VI-B)";
  WriteComparisonPlot(dir_.string(), spec);
  EXPECT_EQ(ExpectClean("comparison.gp"), 1u);
}

// Guards the sweep's charts and `run --runs`' histograms (with paper 2's
// Table 1 figures on them).
TEST_F(FigureLayoutTest, SweepChartsHaveNoOverlaps) {
  SweepChart histogram;
  histogram.file = "beacon_error_x_m_histogram.png";
  histogram.histogram = true;
  histogram.metric = "beacon_error_x_m";
  histogram.run_caption = "van_entry";
  histogram.reference = {"paper 2, Table 1 (20 runs, beacon ground truth)", 0.019, 0.005, 0.004};
  SweepSeries samples;
  for (int k = 0; k < 20; ++k) samples.mean.push_back(0.001 * std::sin(1.7 * k));
  histogram.series = {samples};
  SweepChart numeric;
  numeric.file = "max_path_deviation_m_vs_line.belts.0.speed_mps.png";
  numeric.metric = "max_path_deviation_m";
  numeric.run_caption = "belt_speed_compensation";
  numeric.x_label = "line.belts.0.speed_mps";
  numeric.series = {{"control.compensation=true",
                     {"0.05", "0.1", "0.2"},
                     {0.01, 0.02, 0.04},
                     {0.0, 0.01, 0.03},
                     {0.02, 0.03, 0.05}},
                    {"control.compensation=false",
                     {"0.05", "0.1", "0.2"},
                     {0.05, 0.1, 0.2},
                     {0.04, 0.09, 0.19},
                     {0.06, 0.11, 0.21}}};
  SweepChart categorical;
  categorical.file = "wall_s_vs_master.algorithm.png";
  categorical.metric = "wall_s";
  categorical.x_label = "master.algorithm";
  categorical.categorical_x = true;
  categorical.series = {{"", {"gauss_seidel", "jacobi"}, {1.0, 2.0}, {0.9, 1.8}, {1.1, 2.2}}};
  WriteSweepPlots(dir_.string(), {histogram, numeric, categorical});
  EXPECT_EQ(ExpectClean("sweep_plots.gp"), 3u);
}

// Guards the checker itself: a legend inside the data and two labels on
// one another are found (a check that cannot fail would prove nothing).
TEST_F(FigureLayoutTest, TheCheckerFindsALegendOverTheDataAndOverlappingLabels) {
  std::ofstream(dir_ / "bad.gp")
      << "set terminal pngcairo size 600,400 noenhanced font ',10'\n"
         "set output 'bad.png'\n"
         "set key top left\n"
         "set label 'first label' at 0.5, 0.5\nset label 'second label' at 0.52, 0.5\n"
         "plot [0:1][0:1] x title 'a curve'\n";
  const auto figures = layout::DrawAndRead(dir_.string(), "bad.gp");
  ASSERT_EQ(figures.size(), 1u);
  const auto problems = layout::Problems(figures[0]);
  const auto has = [&](const std::string& what) {
    for (const auto& p : problems) {
      if (p.find(what) != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_TRUE(has("'first label'") && has("overlaps 'second label'"))
      << ::testing::PrintToString(problems);
  EXPECT_TRUE(has("'a curve'") && has("(legend) is inside the plot area"))
      << ::testing::PrintToString(problems);
}

}  // namespace
}  // namespace linesim::plots
