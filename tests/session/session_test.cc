// One run session (session/session.h): what `linesim run`, a sweep's runs
// and the benches run through.
#include "session/session.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>

#include "config/scenario_error.h"

namespace linesim::session {
namespace {

std::string Scenario(const char* name) {
  return std::string(LINESIM_SOURCE_DIR) + "/scenarios/" + name;
}

double Metric(const RunReport& r, const std::string& name) {
  for (const auto& [n, v] : r.metrics) {
    if (n == name) return v;
  }
  ADD_FAILURE() << "no metric " << name;
  return 0.0;
}

// Guards the run: a session gives what the master and the metrics observer
// give when run by hand (the same binary, scenario and seed: the same
// numbers), with its status and summary.
TEST(Session, RunsAScenarioAsTheMasterDoes) {
  const std::vector<std::string> set = {"duration_s=0.5"};
  Session session(Scenario("cross_line.yaml"), set);
  const RunReport report = session.Run();
  ASSERT_TRUE(report.ok()) << report.result.ErrorText();
  EXPECT_STREQ(report.status(), "ok");
  EXPECT_EQ(report.result.end_time, cosim::kNsPerSecond / 2);

  loader::Scenario by_hand = loader::LoadScenario(Scenario("cross_line.yaml"), set);
  cosim::MetricsObserver metrics(by_hand.metrics);
  by_hand.master->AddObserver(&metrics);
  ASSERT_TRUE(by_hand.master->Run().ok);
  const auto expected = metrics.Results();
  ASSERT_EQ(report.metrics.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(report.metrics[i].first, expected[i].first);
    EXPECT_EQ(report.metrics[i].second, expected[i].second) << expected[i].first;
  }

  const auto summary = Summary(session.scenario(), "cross_line.yaml", report);
  EXPECT_EQ(summary["status"], "ok");
  EXPECT_TRUE(summary["error"].is_null());
  EXPECT_EQ(summary["metrics"]["max_path_deviation_m"].get<double>(),
            Metric(report, "max_path_deviation_m"));
  EXPECT_EQ(summary["settings"]["overrides"][0], "duration_s=0.5");
  EXPECT_DOUBLE_EQ(summary["timing"]["simulated_s"].get<double>(), 0.5);
}

// Guards the stop token: a run stopped from outside ends at the next
// communication point, is interrupted (not ok, not failed) and keeps its
// metrics over what ran.
TEST(Session, StopTokenInterruptsAtTheNextStep) {
  Session session(Scenario("motor_step.yaml"));
  std::atomic<bool> stop{true};
  const RunReport report = session.Run(&stop);
  EXPECT_TRUE(report.interrupted);
  EXPECT_FALSE(report.ok());
  EXPECT_STREQ(report.status(), "interrupted");
  EXPECT_TRUE(report.errors.empty());
  EXPECT_EQ(report.result.end_time, session.scenario().master->options().base_step);
}

// Guards Measure (the sweep's metrics): only those asked for, in that
// order; a name the scenario lacks is refused and changes nothing.
// A second run of the same session is refused (its units have run; the
// first run's metrics observer must not be left registered and freed).
TEST(Session, RunsOnce) {
  Session run(Scenario("motor_step.yaml"), {"duration_s=0.1"});
  EXPECT_STREQ(run.Run().status(), "ok");
  EXPECT_THROW(run.Run(), std::logic_error);
}

TEST(Session, MeasuresTheMetricsAskedFor) {
  Session session(Scenario("cross_line.yaml"), {"duration_s=0.2"});
  EXPECT_FALSE(session.Measure({"max_path_deviation_m", "no_such_metric"}));
  ASSERT_TRUE(session.Measure({"collisions", "max_path_deviation_m"}));
  const RunReport report = session.Run();
  ASSERT_EQ(report.metrics.size(), 2u);
  EXPECT_EQ(report.metrics[0].first, "collisions");
  EXPECT_EQ(report.metrics[1].first, "max_path_deviation_m");
}

// Guards the refusal: a bad scenario is refused before anything runs, with
// every problem at its key.
TEST(Session, BadScenarioIsRefusedWithItsProblems) {
  try {
    Session session(Scenario("cross_line.yaml"), {"task.speed_mps=-1", "seed=x"});
    FAIL() << "a bad scenario was accepted";
  } catch (const config::ScenarioError& e) {
    const std::string text = e.what();
    EXPECT_NE(text.find("task.speed_mps"), std::string::npos) << text;
    EXPECT_NE(text.find("seed"), std::string::npos) << text;
  }
}

// Guards a failure found after the run (an output not written): it fails
// the run, with the phase recording, at the run's end time.
TEST(Session, FailureAfterTheRunFailsIt) {
  Session session(Scenario("motor_step.yaml"), {"duration_s=0.01"});
  RunReport report = session.Run();
  ASSERT_TRUE(report.ok());
  report.AddFailure("cannot write signals.csv");
  EXPECT_FALSE(report.ok());
  EXPECT_STREQ(report.status(), "failed");
  EXPECT_EQ(report.errors.front().time, report.result.end_time);
  EXPECT_EQ(report.errors.front().phase, cosim::RunPhase::kRecording);
}

// Guards the plot description's scan geometry: it comes from the system
// description (the mount, the device's numbers from the robot file and the
// model file) and agrees with what the built laser unit holds.
TEST(Session, ScanGeometryOfThePlotsIsTheLasers) {
  const Session session(Scenario("scan_factory.yaml"), {"duration_s=0.1"});
  const loader::Scenario& s = session.scenario();
  ASSERT_TRUE(s.robot.has_value());
  ASSERT_FALSE(s.robot->scan_unit.empty());
  ASSERT_TRUE(s.robot->scan_geometry.has_value());
  const auto& g = *s.robot->scan_geometry;
  const auto index = s.system->FindUnit(s.robot->scan_unit);
  ASSERT_TRUE(index.has_value());
  const cosim::VariableTable& v = s.system->unit(*index).variables();
  const auto real = [&](const char* name) { return v.GetReal(*v.Find(name)); };
  EXPECT_EQ(g.mount_x_m, real("mount_x"));
  EXPECT_EQ(g.mount_y_m, real("mount_y"));
  EXPECT_EQ(g.mount_yaw_rad, real("mount_yaw"));
  EXPECT_EQ(g.first_beam_rad, real("first_beam_angle"));
  EXPECT_EQ(g.beam_step_rad, real("angular_step"));
  EXPECT_EQ(g.no_return_m, real("no_return_value"));
  EXPECT_EQ(static_cast<std::size_t>(g.beams), v.info(*v.Find("ranges")).size);
}

}  // namespace
}  // namespace linesim::session
