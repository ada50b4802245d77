// A run into its folder (session/run_folder.h): the outputs' size bounds
// hold for real runs, and the folder never holds two runs' files while a
// user's own files stay.
#include "session/run_folder.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace linesim::session {
namespace {

namespace fs = std::filesystem;

std::string Scenario(const char* name) {
  return std::string(LINESIM_SOURCE_DIR) + "/scenarios/" + name;
}

std::string Fresh(const std::string& name) {
  const fs::path p = fs::path(::testing::TempDir()) / (name + "_" + std::to_string(getpid()));
  fs::remove_all(p);
  return p.string();
}

std::string ReadFile(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

FolderRun RunInto(const std::string& scenario, const std::vector<std::string>& set,
                  const std::string& dir, FolderOptions options = {}) {
  Session session(scenario, set);
  return RunIntoFolder(session, scenario, dir, options);
}

// Guards the size limit against an estimate a run can pass (issue 37: a
// 72.7 MB replay.html and a 15.9 MB run.mcap under --max-output-mb 1): for
// real runs (a robot crossing the line with PX4Flows and two S300s, a fleet
// with workers, a worker with the safety fields) every file stays under its
// bound. The ratios are printed (how loose each bound is).
TEST(RunFolder, EveryOutputStaysUnderItsBound) {
  struct Case {
    const char* scenario;
    std::vector<std::string> set;
  };
  const std::vector<Case> cases = {{"cross_line.yaml", {"duration_s=3"}},
                                   {"fleet_line.yaml", {"duration_s=1"}},
                                   {"worker_crossing.yaml", {"duration_s=2"}}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.scenario);
    const std::string dir = Fresh("bounds");
    FolderOptions options;
    options.mcap = true;
    Session session(Scenario(c.scenario), c.set);
    const std::vector<OutputBound> bounds = OutputBounds(session.scenario(), options);
    const FolderRun run = RunIntoFolder(session, Scenario(c.scenario), dir, options);
    ASSERT_TRUE(run.report.ok()) << run.report.result.ErrorText();
    ASSERT_EQ(bounds.size(), 4u);
    for (const OutputBound& b : bounds) {
      std::uintmax_t actual = 0;
      if (b.file == "the plots.gp files") {
        for (const auto& e : fs::directory_iterator(dir)) {
          if (e.path().filename().string().ends_with("plots.gp")) actual += e.file_size();
        }
      } else {
        actual = fs::file_size(fs::path(dir) / b.file);
      }
      EXPECT_GT(actual, 0u) << b.file;
      EXPECT_LE(actual, b.bytes) << b.file;
      std::printf("%s %s: %ju bytes, bound %ju (%.2f times)\n", c.scenario, b.file.c_str(), actual,
                  static_cast<std::uintmax_t>(b.bytes),
                  static_cast<double>(b.bytes) / static_cast<double>(actual));
    }
  }
}

// Guards the check itself: over the limit nothing is written (not even the
// folder), and the message names every file with its bound.
TEST(RunFolder, BeyondTheLimitNothingIsWrittenAndEveryFileIsNamed) {
  const std::string dir = Fresh("over_limit");
  FolderOptions options;
  options.mcap = true;
  options.max_output_mb = 1;
  try {
    RunInto(Scenario("cross_line.yaml"), {"duration_s=1000"}, dir, options);
    FAIL() << "a 1000 s run fits 1 MB";
  } catch (const OutputError& e) {
    const std::string what = e.what();
    for (const char* file : {"signals.csv up to", "plots.gp up to", "replay.html up to",
                             "run.mcap up to", "more than the 1 MB allowed (--max-output-mb)"}) {
      EXPECT_NE(what.find(file), std::string::npos) << file << " in: " << what;
    }
  }
  EXPECT_FALSE(fs::exists(dir));
}

std::vector<std::string> Names(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// Guards the folder holding one run's files (issue 37: a fleet run then a
// one-robot run left the fleet's other robots' plots): a run removes every
// file the previous run's summary lists and nothing a user put there, also
// files named like a robot's plots that no run wrote.
TEST(RunFolder, ANewRunLeavesNoFileOfThePreviousOneAndKeepsTheUsers) {
  const std::string dir = Fresh("one_run");
  ASSERT_TRUE(RunInto(Scenario("fleet_line.yaml"), {"duration_s=0.2"}, dir).report.ok());
  ASSERT_TRUE(fs::exists(fs::path(dir) / "raw3_b_top_view.png"));
  ASSERT_TRUE(fs::exists(fs::path(dir) / "husky_plots.gp"));
  for (const char* user : {"notes.txt", "my_top_view.png", "husky2_top_view.png"}) {
    std::ofstream(fs::path(dir) / user) << "the user's";
  }
  ASSERT_TRUE(RunInto(Scenario("cross_line.yaml"), {"duration_s=0.2"}, dir).report.ok());
  const std::string again = Fresh("one_run_alone");
  ASSERT_TRUE(RunInto(Scenario("cross_line.yaml"), {"duration_s=0.2"}, again).report.ok());
  std::vector<std::string> expected = Names(again);
  for (const char* user : {"notes.txt", "my_top_view.png", "husky2_top_view.png"}) {
    expected.push_back(user);
    EXPECT_EQ(ReadFile(fs::path(dir) / user), "the user's") << user;
  }
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(Names(dir), expected);
}

// Guards a killed run's files: its summary.json (the one written at the
// start) lists every file it may write, so the next run removes a plot it
// left half drawn, even one of a robot the next run does not have.
TEST(RunFolder, AKilledRunsFilesGoByItsStartingSummary) {
  const std::string dir = Fresh("killed");
  const std::string outside = "outside_" + std::to_string(getpid()) + ".txt";
  fs::create_directories(dir);
  nlohmann::json started = {{"scenario", "fleet_line"},
                            {"status", "failed"},
                            {"outputs",
                             {"summary.json", "signals.csv", "raw3_b_plots.gp",
                              "raw3_b_top_view.png", "../" + outside, "notes.txt"}}};
  std::ofstream(fs::path(dir) / "summary.json") << started.dump();
  for (const char* left :
       {"raw3_b_plots.gp", "raw3_b_top_view.png", "raw3_b_plots.gp.tmp", "notes.txt"}) {
    std::ofstream(fs::path(dir) / left) << "x";
  }
  std::ofstream(fs::path(dir).parent_path() / outside) << "x";
  ASSERT_TRUE(RunInto(Scenario("motor_step.yaml"), {}, dir).report.ok());
  for (const char* gone : {"raw3_b_plots.gp", "raw3_b_top_view.png", "raw3_b_plots.gp.tmp"}) {
    EXPECT_FALSE(fs::exists(fs::path(dir) / gone)) << gone;
  }
  // Only names a run writes count, and only inside the folder.
  EXPECT_TRUE(fs::exists(fs::path(dir) / "notes.txt"));
  EXPECT_TRUE(fs::exists(fs::path(dir).parent_path() / outside));
  // The new summary lists the new run's files.
  const auto summary = nlohmann::json::parse(ReadFile(fs::path(dir) / "summary.json"));
  EXPECT_EQ(summary["outputs"], nlohmann::json({"summary.json", "signals.csv"}));
}

}  // namespace
}  // namespace linesim::session
