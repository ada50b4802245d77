#include "plots/robot_plots.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace linesim::plots {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, with a space and a quote in its name so that any
// quoting mistake in running gnuplot shows; removed afterwards.
class RobotPlotsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("linesim plots 'test' " + std::to_string(getpid()) + " " + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A synthetic run in the recorder's format: a Rob@Work-3-sized robot
  // crossing a belt along +y over 30 s, recorded every 10 ms (3001 rows, the
  // size the brief asks to plot quickly), wheels at the raw3-1 steering axes
  // (docs/references.md), a belt that runs from 0 to 10 s and ramps up at 0.5 m/s^2.
  void WriteSignals(double speed_mps = 0.1) const {
    std::ofstream out(dir_ / "signals.csv");
    out << "time,chassis.pose[0],chassis.pose[1],chassis.pose[2]";
    for (int w = 0; w < 4; ++w)
      out << ",chassis.contact_x[" << w << "],chassis.contact_y[" << w << "]";
    out << ",metrics.deviation,belt.speed[0],belt.on[0]\n";
    const double wheel_x[4] = {0.368, -0.368, -0.368, 0.368};
    const double wheel_y[4] = {0.186, 0.134, -0.186, -0.134};
    for (int k = 0; k <= 3000; ++k) {
      const double t = 0.01 * k;
      const double x = 0.02 * std::sin(t), y = -1.5 + speed_mps * t, yaw = 0.5 * std::numbers::pi;
      out << t << "," << x << "," << y << "," << yaw;
      for (int w = 0; w < 4; ++w) {
        out << "," << x + std::cos(yaw) * wheel_x[w] - std::sin(yaw) * wheel_y[w] << ","
            << y + std::sin(yaw) * wheel_x[w] + std::cos(yaw) * wheel_y[w];
      }
      const bool on = t < 10.0;
      const double speed = on ? std::min(0.1, 0.5 * t) : std::max(0.0, 0.1 - 0.5 * (t - 10.0));
      out << "," << std::abs(x) << "," << speed << "," << (on ? 1 : 0) << "\n";
    }
  }

  static RobotPlotSpec Spec() {
    RobotPlotSpec spec;
    spec.run_caption = "crossing 'test'";
    models::Belt belt;
    belt.name = "line";
    belt.area = {0.0, 0.0, 10.0, 1.0, 0.0};
    spec.scene.belts = {belt};
    spec.path_m = {{0.0, -1.5}, {0.0, 1.5}};
    spec.x_column = "chassis.pose[0]";
    spec.y_column = "chassis.pose[1]";
    spec.yaw_column = "chassis.pose[2]";
    for (int w = 0; w < 4; ++w) {
      spec.wheel_columns.emplace_back("chassis.contact_x[" + std::to_string(w) + "]",
                                      "chassis.contact_y[" + std::to_string(w) + "]");
    }
    spec.error_column = "metrics.deviation";
    spec.error_label = "deviation from path";
    spec.belt_speed_columns = {"belt.speed[0]"};
    spec.belt_on_columns = {"belt.on[0]"};
    return spec;
  }

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

  fs::path dir_;
};

// Guards against a run that silently produces no plots, broken files, or a
// script the user cannot re-run: all three PNGs are real PNG files, and
// plots.gp holds its data (no file name in it: it redraws anywhere).
TEST_F(RobotPlotsTest, WritesTheThreePngsAndTheScript) {
  WriteSignals();
  const auto files = WriteRobotPlots(dir_.string(), Spec());
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(fs::path(files[0]).filename(), "top_view.png");
  EXPECT_EQ(fs::path(files[1]).filename(), "error.png");
  EXPECT_EQ(fs::path(files[2]).filename(), "belt.png");
  for (const auto& f : files) EXPECT_TRUE(IsPng(f)) << f;
  const std::string script = ReadAll(dir_ / "plots.gp");
  EXPECT_EQ(script.find("'signals.csv'"), std::string::npos);
  // The time plots' columns, copied from each of the 3001 rows as the text
  // signals.csv holds: time, x, y, the deviation, the belt's speed and state.
  const std::string block = "$signals << EOD\n";
  const auto data = script.find(block);
  ASSERT_NE(data, std::string::npos);
  const auto data_end = script.find("EOD\n", data + block.size());
  const std::string rows = script.substr(data + block.size(), data_end - data - block.size());
  EXPECT_EQ(std::count(rows.begin(), rows.end(), '\n'), 3001);
  EXPECT_EQ(rows.substr(0, rows.find('\n')), "0,0,-1.5,0,0,1");
  EXPECT_NE(script.find("$signals using 2:3 with lines"), std::string::npos);
  EXPECT_NE(script.find("set size ratio -1"), std::string::npos);
  // 5 outlines of the robot by default, each a closed 5-point polygon plus a
  // 2-point heading tick; 4 wheel contacts at each of those instants.
  EXPECT_NE(script.find("$outlines << EOD"), std::string::npos);
  const std::string head = "$contacts << EOD\n";
  const auto begin = script.find(head);
  ASSERT_NE(begin, std::string::npos);
  const auto end = script.find("EOD\n", begin + head.size());
  int lines = 0;
  for (auto i = begin + head.size(); i < end; ++i) lines += script[i] == '\n';
  EXPECT_EQ(lines, 20);
}

// Guards the side view of a climb: a robot driving along +x over a ramp
// whose top face rises 0.54 m over 2 m from x = 2 (the van bay's), its
// base_link 0.1 m above the ground: side_view.png is drawn with the ground
// under the track from the scene's terrain (0 on the floor, 0.27 m at the
// ramp's middle x = 3, the 1-D interpolation of the top face).
TEST_F(RobotPlotsTest, SideViewDrawsTheHeightOverTheGround) {
  {
    std::ofstream out(dir_ / "signals.csv");
    out << "time,chassis.position_3d[0],chassis.position_3d[1],chassis.position_3d[2]\n";
    for (int k = 0; k <= 50; ++k) {
      const double x = 0.1 * k, ground = std::clamp((x - 2.0) * 0.27, 0.0, 0.54);
      out << 0.5 * k << "," << x << ",0," << ground + 0.1 << "\n";
    }
  }
  RobotPlotSpec spec;
  spec.x_column = "chassis.position_3d[0]";
  spec.y_column = "chassis.position_3d[1]";
  spec.z_column = "chassis.position_3d[2]";
  models::TerrainPiece ramp;
  ramp.pitch_rad = std::atan2(0.54, 2.0);
  ramp.length_m = std::hypot(2.0, 0.54);
  ramp.width_m = 1.2;
  ramp.thickness_m = 0.0;
  ramp.center_x_m = 3.0;
  ramp.center_z_m = 0.27;
  spec.scene.terrain = {ramp};
  const auto files = WriteRobotPlots(dir_.string(), spec);
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(fs::path(files[1]).filename(), "side_view.png");
  EXPECT_TRUE(IsPng(files[1]));
  const std::string script = ReadAll(dir_ / "plots.gp");
  // Row 30: 3 m travelled, base_link at 0.37 m over ground at 0.27 m.
  EXPECT_NE(script.find("\n3,0.37,0.27"), std::string::npos) << script.substr(0, 400);
  EXPECT_NE(script.find("\n1,0.1,0\n"), std::string::npos);
}

// Guards against the safety plot missing or drawing the wrong columns: a
// robot at 0.3 m/s stopped by its protective field from 2 s to 4 s, with a
// worker walking beside it. safety.png is drawn from the velocity, cap and
// field columns, the cap of -1 (none) left out, and the top view draws the
// worker's track.
TEST_F(RobotPlotsTest, SafetyPlotDrawsSpeedCapAndFields) {
  {
    std::ofstream out(dir_ / "signals.csv");
    out << "time,chassis.position[0],chassis.position[1],chassis.linear_velocity[0],"
           "chassis.linear_velocity[1],safety.speed_cap,safety.protective_clear,"
           "safety.warning_clear,person_clearance.distance,worker.pose[0],worker.pose[1]\n";
    for (int k = 0; k <= 60; ++k) {
      const double t = 0.1 * k;
      const bool stopped = t >= 2.0 && t < 4.0;
      out << t << ",0," << 0.3 * t << ",0," << (stopped ? 0.0 : 0.3) << ","
          << (stopped ? 0.0 : -1.0) << "," << (stopped ? 0 : 1) << "," << (t >= 1.5 ? 0 : 1) << ","
          << 1.0 - 0.1 * t << "," << -2.0 + 0.3 * t << ",1\n";
    }
  }
  RobotPlotSpec spec;
  spec.x_column = "chassis.position[0]";
  spec.y_column = "chassis.position[1]";
  spec.safety = {"chassis.linear_velocity[0]",
                 "chassis.linear_velocity[1]",
                 "safety.speed_cap",
                 "safety.protective_clear",
                 "safety.warning_clear",
                 "person_clearance.distance",
                 "",
                 {}};
  RobotPlotSpec::Worker worker;
  worker.name = "worker";
  worker.x_column = "worker.pose[0]";
  worker.y_column = "worker.pose[1]";
  spec.workers = {worker};
  const auto files = WriteRobotPlots(dir_.string(), spec);
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(fs::path(files[1]).filename(), "safety.png");
  EXPECT_TRUE(IsPng(files[1]));
  const std::string script = ReadAll(dir_ / "plots.gp");
  // $signals columns: velocity 4 and 5, cap 6 (-1: NaN), the distance 7
  // in a panel of its own (not on the speed's axis, not cut off); each
  // field a lane, barred over the spans it is infringed (protective 2-4 s,
  // warning from 1.5 s to the end); the closest approach (0.4 m at 6 s)
  // marked; the worker's track in the top view, named, from a data block
  // the script carries.
  EXPECT_NE(script.find("sqrt(column(4)**2 + column(5)**2)"), std::string::npos);
  EXPECT_NE(script.find("column(6) < 0 ? NaN : column(6)"), std::string::npos);
  EXPECT_NE(script.find("set object rectangle from first 2, first 0.7 to first 4, first 1.3"),
            std::string::npos)
      << script;
  EXPECT_NE(script.find("set object rectangle from first 1.5, first -0.3 to first 6, first 0.3"),
            std::string::npos)
      << script;
  EXPECT_NE(script.find("$signals using 1:7 with lines"), std::string::npos) << script;
  EXPECT_EQ(script.find("1.5 ? NaN"), std::string::npos) << script;
  EXPECT_NE(script.find("$closest << EOD\n6,0.4\n"), std::string::npos) << script;
  EXPECT_NE(script.find("closest approach: 0.4 m at t = 6 s"), std::string::npos) << script;
  EXPECT_NE(script.find("$worker_track_0 using 1:2 with lines"), std::string::npos);
  EXPECT_NE(script.find("title 'worker: walk'"), std::string::npos);
  EXPECT_NE(script.find("$worker_track_0 << EOD"), std::string::npos);
}

// Guards against output that changes from run to run (timestamps, map
// order): the same input gives the same script and the same PNG bytes.
TEST_F(RobotPlotsTest, IsDeterministic) {
  WriteSignals();
  WriteRobotPlots(dir_.string(), Spec());
  const std::string script = ReadAll(dir_ / "plots.gp");
  const std::string png = ReadAll(dir_ / "top_view.png");
  WriteRobotPlots(dir_.string(), Spec());
  EXPECT_EQ(ReadAll(dir_ / "plots.gp"), script);
  EXPECT_EQ(ReadAll(dir_ / "top_view.png"), png);
}

// Guards the streaming read: a file with a header and no rows (blank and
// CR-only lines are no rows) is refused by name, not drawn empty.
TEST_F(RobotPlotsTest, SignalsWithoutRowsAreRefused) {
  WriteSignals();
  const std::string all = ReadAll(dir_ / "signals.csv");
  std::ofstream(dir_ / "signals.csv") << all.substr(0, all.find('\n') + 1) << "\n\r\n";
  try {
    WriteRobotPlots(dir_.string(), Spec());
    FAIL() << "a file without rows was drawn";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("signals.csv has no data rows"), std::string::npos)
        << e.what();
  }
}

// Guards against an unknown column being plotted as garbage or reported
// vaguely: every unknown name is in the message with the closest real one.
TEST_F(RobotPlotsTest, UnknownColumnIsNamed) {
  WriteSignals();
  RobotPlotSpec spec = Spec();
  spec.yaw_column = "chassis.pose[7]";
  spec.belt_on_columns = {"belt.of[0]"};
  try {
    WriteRobotPlots(dir_.string(), spec);
    FAIL() << "an unknown column was accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no column 'chassis.pose[7]' (robot yaw)"), std::string::npos) << what;
    EXPECT_NE(what.find("no column 'belt.of[0]' (belt on)"), std::string::npos) << what;
    EXPECT_NE(what.find("belt.on[0]"), std::string::npos) << what;  // the closest name
  }
  EXPECT_FALSE(fs::exists(dir_ / "top_view.png"));
}

// Guards against plots that are always drawn: without an error column or
// belt columns only the top view is written; a single path point (a hold
// target) and no yaw (no outlines) still give a valid plot.
TEST_F(RobotPlotsTest, WritesOnlyWhatTheSpecAsksFor) {
  WriteSignals();
  RobotPlotSpec spec = Spec();
  spec.error_column.clear();
  spec.belt_speed_columns.clear();
  spec.belt_on_columns.clear();
  spec.yaw_column.clear();
  spec.path_m = {{0.0, 0.0}};
  const auto files = WriteRobotPlots(dir_.string(), spec);
  ASSERT_EQ(files.size(), 1u);
  EXPECT_TRUE(IsPng(files[0]));
  EXPECT_FALSE(fs::exists(dir_ / "error.png"));
  const std::string script = ReadAll(dir_ / "plots.gp");
  EXPECT_NE(script.find("hold target"), std::string::npos);
  EXPECT_EQ(script.find("$outlines"), std::string::npos);
}

// Guards the top view of a robot that holds its place (the hold
// scenarios): its five time labels would be printed over each other, so
// they join into one (without commas, the data separator).
TEST_F(RobotPlotsTest, StandingRobotGetsOneJoinedTimeLabel) {
  WriteSignals(0.0);
  WriteRobotPlots(dir_.string(), Spec());
  const std::string script = ReadAll(dir_ / "plots.gp");
  EXPECT_NE(script.find(",t = 0 / 7.5 / 15 / 22.5 / 30 s\n"), std::string::npos) << script;
}

// Guards the scene in the top view: obstacles near the path are drawn and
// framed (boxes as filled outlines, cylinders as circles), one far away does
// not stretch the view (nor is it listed), and a carried object appears
// where it is in view: at the end, moved along its belt by the travel
// column's last value.
TEST_F(RobotPlotsTest, DrawsObstaclesAndCarriedObjects) {
  WriteSignals();
  {
    // A travel column: the belt surface at 0.1 m/s for 30 s travels 3 m.
    std::ifstream in(dir_ / "signals.csv");
    std::string line, out;
    std::getline(in, line);
    out = line + ",belt.travel[0]\n";
    for (int k = 0; std::getline(in, line); ++k)
      out += line + "," + std::to_string(0.001 * k) + "\n";
    in.close();
    std::ofstream(dir_ / "signals.csv") << out;
  }
  RobotPlotSpec spec = Spec();
  models::Obstacle cart{"cart", "cart", {}};
  cart.solid.x_m = 1.0;  // 1 m beside the path at x = 0
  cart.solid.length_m = 1.2;
  cart.solid.width_m = 0.8;
  cart.solid.height_m = 1.0;
  models::Obstacle pillar{"pillar", "pillar", {}};
  pillar.solid.kind = models::Solid::Kind::kCylinder;
  pillar.solid.x_m = -1.0;
  pillar.solid.radius_m = 0.25;
  pillar.solid.height_m = 4.0;
  models::Obstacle far_wall{"wall", "wall", {}};
  far_wall.solid.x_m = 50.0;
  far_wall.solid.length_m = 0.2;
  far_wall.solid.width_m = 20.0;
  far_wall.solid.height_m = 4.0;
  spec.scene.obstacles = {cart, pillar, far_wall};
  models::CarriedObject body{"body", 0, {}};
  body.solid.x_m = -3.0;
  body.solid.length_m = 2.0;
  body.solid.width_m = 0.8;
  body.solid.height_m = 1.2;
  spec.scene.carried = {body};
  spec.belt_travel_columns = {"belt.travel[0]"};
  const auto files = WriteRobotPlots(dir_.string(), spec);
  ASSERT_FALSE(files.empty());
  EXPECT_TRUE(IsPng(files[0]));
  const std::string script = ReadAll(dir_ / "plots.gp");
  // The cart's polygon starts at its front-left corner (1.6, 0.4).
  EXPECT_NE(script.find("$obstacles << EOD\n1.6,0.4\n"), std::string::npos) << script;
  EXPECT_NE(script.find("$obstacles_circles << EOD\n-1,0,0.25\n"), std::string::npos) << script;
  EXPECT_NE(script.find("with circles"), std::string::npos);
  // Time zero: the body spans x -4 to -2, beyond 1.5 m (near_m) of the
  // path: out of the view, neither drawn nor in the legend; the end: moved
  // 3 m along +x onto the path, front-left corner at (1, 0.4).
  EXPECT_EQ(script.find("$carried << EOD"), std::string::npos) << script;
  EXPECT_EQ(script.find("carried object (t = 0)"), std::string::npos) << script;
  EXPECT_NE(script.find("$carried_end << EOD\n1,0.4\n"), std::string::npos) << script;
  // The wall at x = 50 is not near the path: the view stays within 10 m.
  const auto at = script.find("set xrange [");
  ASSERT_NE(at, std::string::npos);
  const double x_max = std::stod(script.substr(script.find(':', at) + 1));
  EXPECT_LT(x_max, 10.0);
}

// Guards against a missing signals.csv or gnuplot being reported as
// something else: both errors say what is missing.
TEST_F(RobotPlotsTest, MissingInputOrGnuplotIsAClearError) {
  try {
    WriteRobotPlots(dir_.string(), Spec());
    FAIL() << "no signals.csv was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("signals.csv"), std::string::npos) << e.what();
  }
  WriteSignals();
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", (dir_ / "nowhere").c_str(), 1);
  try {
    WriteRobotPlots(dir_.string(), Spec());
    ADD_FAILURE() << "gnuplot ran without a PATH to it";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot run gnuplot"), std::string::npos) << e.what();
  }
  setenv("PATH", path.c_str(), 1);
}

// Guards against gnuplot's own errors being swallowed: a file that is not
// numbers where gnuplot expects a column fails the run with gnuplot's text.
TEST_F(RobotPlotsTest, GnuplotFailureCarriesItsErrorText) {
  // Only a header and a row with too few fields: the position columns do not
  // exist in the data, so gnuplot finds no valid points to autoscale on.
  std::ofstream(dir_ / "signals.csv") << "time,a,b\n0\n";
  RobotPlotSpec spec;
  spec.x_column = "a";
  spec.y_column = "b";
  try {
    WriteRobotPlots(dir_.string(), spec);
    FAIL() << "gnuplot's failure was not reported";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("gnuplot failed"), std::string::npos) << what;
    EXPECT_NE(what.find("plots.gp"), std::string::npos) << what;
  }
}

// Guards paper 1 Figs. 5 and 7 as error.png draws them: the curve under
// the user's name (not the column's), in mm, the 4 cm bound of paper 1
// Sec. VI-B as a line at 40 mm with its legend entry, the spans the belt
// is scheduled on (0-10 s in the synthetic run) marked in a band along the
// top from its on column, time from the first row to the last (not to the
// next tic), and the legend below the data.
TEST_F(RobotPlotsTest, ErrorPlotDrawsTheBoundTheLineStateAndTheUsersNames) {
  WriteSignals();
  RobotPlotSpec spec = Spec();
  spec.error_name = "deviation of the robot's centre from the desired path";
  spec.error_bound = {0.04, "4 cm (paper 1, Sec. VI-B)", ""};
  WriteRobotPlots(dir_.string(), spec);
  const std::string script = ReadAll(dir_ / "plots.gp");
  const auto at = script.find("set output 'error.png'");
  ASSERT_NE(at, std::string::npos) << script;
  const std::string error = script.substr(at, script.find("set output", at + 1) - at);
  EXPECT_NE(error.find("title 'deviation of the robot''s centre from the desired path'"),
            std::string::npos)
      << error;
  EXPECT_EQ(error.find("title 'metrics.deviation'"), std::string::npos) << error;
  EXPECT_NE(error.find("$signals using 1:4 with lines"), std::string::npos) << error;
  EXPECT_NE(error.find("set ylabel 'deviation from path (mm)'"), std::string::npos) << error;
  EXPECT_NE(error.find("40 with lines dt 2 lw 2 lc rgb '#000000'"), std::string::npos) << error;
  EXPECT_NE(error.find("title '4 cm (paper 1, Sec. VI-B)'"), std::string::npos) << error;
  // belt.on[0] is on from 0 to 10 s: a band at the top over that span.
  EXPECT_NE(error.find("set object rectangle from first 0, graph 0.97 to first 10, graph 1"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("title 'line on (band along the top)'"), std::string::npos) << error;
  EXPECT_NE(error.find("set xrange [0:30]"), std::string::npos) << error;
  EXPECT_NE(error.find("set key at screen 0.5, 0.01 center bottom"), std::string::npos) << error;
}

// Guards a bound on the final pose (paper 2's Table 1 on van_entry): drawn
// from the time the task's done column rose (12 s here) to the end, in mm,
// not across the whole run.
TEST_F(RobotPlotsTest, FinalPoseBoundIsDrawnFromTheTasksEnd) {
  WriteSignals();
  {
    std::ifstream in(dir_ / "signals.csv");
    std::string line, out;
    std::getline(in, line);
    out = line + ",path_follower.done\n";
    for (int k = 0; std::getline(in, line); ++k) out += line + (k >= 1200 ? ",1\n" : ",0\n");
    in.close();
    std::ofstream(dir_ / "signals.csv") << out;
  }
  RobotPlotSpec spec = Spec();
  spec.error_bound = {0.014, "paper 2, Table 1", "path_follower.done"};
  WriteRobotPlots(dir_.string(), spec);
  const std::string script = ReadAll(dir_ / "plots.gp");
  EXPECT_NE(script.find("$bound << EOD\n12,14\n30,14\nEOD\n"), std::string::npos) << script;
  EXPECT_NE(script.find("$bound using 1:2 with lines dt 2"), std::string::npos) << script;
}

// Guards paper 1 Fig. 4 as optic_flow.png draws it: a panel per sensor
// (named), each with its raw reading (the surface relative to the sensor),
// its true reading, its filtered value and the ground truth; one legend
// of five kinds (not thirteen entries) below the panels.
TEST_F(RobotPlotsTest, OpticFlowHasAPanelPerSensorAndOneShortLegend) {
  {
    std::ofstream out(dir_ / "signals.csv");
    out << "time,x,y";
    for (int k = 0; k < 4; ++k) out << ",raw[" << k << "],filtered[" << k << "],true[" << k << "]";
    out << ",truth,on\n";
    for (int i = 0; i <= 100; ++i) {
      out << 0.1 * i << ",0,0";
      for (int k = 0; k < 4; ++k) out << "," << 0.2 + 0.01 * (k - 2) << ",0.2,0.2";
      out << ",0.2,1\n";
    }
  }
  RobotPlotSpec spec;
  spec.x_column = "x";
  spec.y_column = "y";
  for (int k = 0; k < 4; ++k) {
    spec.flow_columns.push_back("raw[" + std::to_string(k) + "]");
    spec.flow_filtered_columns.push_back("filtered[" + std::to_string(k) + "]");
    spec.flow_truth_columns.push_back("true[" + std::to_string(k) + "]");
    spec.flow_labels.push_back("optic_flow_" + std::to_string(k));
  }
  spec.flow_reference_column = "truth";
  spec.belt_on_columns = {"on"};
  const auto files = WriteRobotPlots(dir_.string(), spec);
  ASSERT_EQ(files.size(), 3u);  // top view, belt (its on state), optic flow
  const std::string script = ReadAll(dir_ / "plots.gp");
  const std::string flow = script.substr(script.find("set output 'optic_flow.png'"));
  EXPECT_NE(flow.find("set multiplot"), std::string::npos) << flow;
  for (int k = 0; k < 4; ++k) {
    EXPECT_NE(flow.find("set title 'optic_flow_" + std::to_string(k) + "'"), std::string::npos)
        << flow;
  }
  EXPECT_NE(flow.find("set key at screen 0.5, 0.01 center bottom"), std::string::npos) << flow;
  // Legend entries: plot items with a title (not the panels' or the
  // caption's `set ... title`).
  const auto count = [&](const std::string& what) {
    std::size_t n = 0;
    for (auto at = flow.find(what); at != std::string::npos; at = flow.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count(" title '") - count("set title '") - count("multiplot title '"), 5u)
      << flow;  // the line's band and four kinds, once
  EXPECT_NE(flow.find("PX4Flow reading (the surface relative to the sensor)"), std::string::npos);
  EXPECT_NE(flow.find("the same from ground truth"), std::string::npos);
  EXPECT_NE(flow.find("filtered: the surface speed (Eq. 2)"), std::string::npos);
}

// Guards --format svg and pdf: the pictures are written in the format asked
// for (the same names, another extension), each a valid file of its kind
// (an SVG document with its root element closed and the legend's text in
// it; a PDF starting with its header, ISO 32000-1 sec. 7.5.2), and the
// script names them.
TEST_F(RobotPlotsTest, VectorFormatsWriteSvgAndPdf) {
  WriteSignals();
  RobotPlotSpec spec = Spec();
  spec.error_bound = {0.04, "4 cm (paper 1, Sec. VI-B)", ""};
  spec.format = PlotFormat::kSvg;
  auto files = WriteRobotPlots(dir_.string(), spec);
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(fs::path(files[1]).filename(), "error.svg");
  for (const auto& f : files) {
    const std::string svg = ReadAll(f);
    EXPECT_EQ(svg.rfind("<?xml", 0), 0u) << f;
    EXPECT_NE(svg.find("<svg"), std::string::npos) << f;
    EXPECT_NE(svg.find("</svg>"), std::string::npos) << f;
  }
  const std::string error = ReadAll(files[1]);
  EXPECT_NE(error.find("4 cm (paper 1, Sec. VI-B)"), std::string::npos);
  EXPECT_NE(error.find("line on"), std::string::npos);
  EXPECT_NE(ReadAll(dir_ / "plots.gp").find("set terminal svg"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "error.png"));

  spec.format = PlotFormat::kPdf;
  files = WriteRobotPlots(dir_.string(), spec);
  ASSERT_EQ(files.size(), 3u);
  for (const auto& f : files) {
    EXPECT_EQ(fs::path(f).extension(), ".pdf");
    EXPECT_EQ(ReadAll(f).rfind("%PDF-", 0), 0u) << f;
  }
}

TEST(PlotFormat, NamesAndExtensions) {
  EXPECT_EQ(ParsePlotFormat("svg"), PlotFormat::kSvg);
  EXPECT_EQ(ParsePlotFormat("pdf"), PlotFormat::kPdf);
  EXPECT_EQ(ParsePlotFormat("png"), PlotFormat::kPng);
  EXPECT_EQ(ParsePlotFormat("jpeg"), std::nullopt);
  EXPECT_EQ(PlotFile("error", PlotFormat::kPdf), "error.pdf");
  // Every format's pictures are among the files a new run clears.
  const auto all = RobotPlotFiles();
  for (const char* name : {"plots.gp", "error.png", "error.svg", "optic_flow.pdf"}) {
    EXPECT_NE(std::find(all.begin(), all.end(), name), all.end()) << name;
  }
  // A fleet's other robot's, by its prefix.
  const auto raw3_b = RobotPlotFiles("raw3_b_");
  for (const char* name : {"raw3_b_plots.gp", "raw3_b_top_view.png", "raw3_b_safety.svg"}) {
    EXPECT_NE(std::find(raw3_b.begin(), raw3_b.end(), name), raw3_b.end()) << name;
  }
}

}  // namespace
}  // namespace linesim::plots
