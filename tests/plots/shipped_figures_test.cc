// Every figure the shipped scenarios, `run --runs`, a sweep and a
// comparison draw, from real runs of the command line, checked by
// gnuplot's own layout (tests/plots/figure_layout.h): no text overlaps
// another, none leaves the canvas, no legend entry lies in a plot area.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "figure_layout.h"

namespace linesim::plots {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = LINESIM_SOURCE_DIR;

std::string ReadAll(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct Case {
  std::string name;
  std::string file;     // what the command line runs, relative to the source tree
  std::string options;  // besides --out
};

class ShippedFigures : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("linesim shipped figures " + std::to_string(getpid()) + " " + GetParam().name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // Runs `linesim run FILE --out DIR/out OPTIONS` (or `sweep`); fails the
  // test with its output when it fails.
  fs::path Run(const std::string& command, const fs::path& file, const std::string& options) {
    const fs::path out = dir_ / "out";
    const std::string line = std::string(LINESIM_CLI) + " " + command + " '" + file.string() +
                             "' --out '" + out.string() + "' " + options + " > '" +
                             (dir_ / "log.txt").string() + "' 2>&1";
    const int status = std::system(line.c_str());
    EXPECT_EQ(status, 0) << line << "\n" << ReadAll(dir_ / "log.txt");
    return out;
  }

  // Checks every gnuplot script in `folder` and its run folders.
  void CheckScripts(const fs::path& folder) {
    std::size_t figures = 0;
    for (const auto& entry : fs::recursive_directory_iterator(folder)) {
      const fs::path p = entry.path();
      if (p.extension() != ".gp" || p.filename().string().rfind("layout_", 0) == 0) continue;
      for (const auto& f : layout::DrawAndRead(p.parent_path().string(), p.filename().string())) {
        ++figures;
        for (const auto& problem : layout::Problems(f)) {
          ADD_FAILURE() << p.filename() << " " << f.file << ": " << problem;
        }
      }
    }
    EXPECT_GT(figures, 0u) << folder;
  }

  fs::path dir_;
};

// Guards each shipped scenario's figures (and the runs' statistics, a
// sweep, the comparison) against labels over labels and legends over data.
TEST_P(ShippedFigures, HaveNoOverlapsAndLegendsOutsideTheData) {
  const Case& c = GetParam();
  fs::path file = kSource / c.file;
  std::string command = "run";
  if (c.name == "fleet_line_scans") {
    // The fleet with every robot's front scan drawn: a copy of the shipped
    // file whose robots each take a snapshot (the Husky's scan meets the
    // other robots and the workers).
    std::string text = ReadAll(file);
    for (const char* robot : {"  - name: raw3_a\n", "  - name: husky\n"}) {
      const auto at = text.find(robot);
      ASSERT_NE(at, std::string::npos) << "fleet_line.yaml has no " << robot;
      text.insert(at + std::string(robot).size(), "    sensors: {laser_front: {snapshot_s: 14}}\n");
    }
    file = dir_ / "fleet_scans.yaml";
    std::ofstream(file) << text;
  }
  if (c.name == "sweep") {
    file = dir_ / "sweep.yaml";
    std::ofstream(file) << "name: figures_sweep\nscenario: "
                        << (kSource / "scenarios/cross_line.yaml").string()
                        << "\nset: {duration_s: 12}\nparameters:\n"
                           "  - path: line.belts.0.speed_mps\n    values: [0.05, 0.15]\n"
                           "  - path: control.compensation\n    values: [true, false]\n"
                           "seed: 1\nmetrics: [max_path_deviation_m, min_clearance_m]\n";
    command = "sweep";
  }
  CheckScripts(Run(command, file, c.options));
}

INSTANTIATE_TEST_SUITE_P(
    Scenarios, ShippedFigures,
    ::testing::Values(
        Case{"cross_line", "scenarios/cross_line.yaml", "--no-replay"},
        Case{"hold_on_belt", "scenarios/hold_on_belt.yaml", "--no-replay"},
        Case{"hold_straddle", "scenarios/hold_straddle.yaml", "--no-replay"},
        Case{"optic_flow_profile", "scenarios/optic_flow_profile.yaml", "--no-replay"},
        Case{"scan_factory", "scenarios/scan_factory.yaml", "--no-replay"},
        Case{"worker_crossing", "scenarios/worker_crossing.yaml", "--no-replay"},
        Case{"van_entry", "scenarios/van_entry.yaml", "--no-replay"},
        Case{"husky_floor_path", "scenarios/husky_floor_path.yaml", "--no-replay"},
        // Its figures are cross_line's kinds over 150 s; 60 s of it
        // has the car bodies pass.
        Case{"line_traffic", "scenarios/line_traffic.yaml", "--no-replay --set duration_s=60"},
        Case{"fleet_line_scans", "scenarios/fleet_line.yaml", "--no-replay"},
        Case{"nominal_vs_modified", "scenarios/nominal_vs_modified.yaml", ""},
        // Paper 2's Table 1 as `run --runs` draws it: a histogram
        // per metric with the source's figures.
        Case{"van_entry_runs", "scenarios/van_entry.yaml", "--runs 3"}, Case{"sweep", "", ""}),
    [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace
}  // namespace linesim::plots
