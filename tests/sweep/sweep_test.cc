// The sweep library with the real loader and units: sweep files, the run
// plan, results.csv and the threaded executor.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "config/scenario_error.h"
#include "sweep/executor.h"
#include "sweep/progress.h"
#include "sweep/results_file.h"
#include "sweep/run_one.h"
#include "sweep/run_plan.h"
#include "sweep/sweep_spec.h"

namespace linesim::sweep {
namespace {

namespace fs = std::filesystem;

const std::string kCrossLine = LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml";

std::string WriteFile(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "sweep_" + std::to_string(getpid()) + "_" + name;
  std::ofstream(path) << text;
  return path;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The shipped belt-speed x compensation sweep, shortened to 2 s runs.
std::string BeltSweep(const std::string& extra = "") {
  return "name: belt\n"
         "scenario: " +
         kCrossLine +
         "\n"
         "set: {duration_s: 2}\n"
         "parameters:\n"
         "  - {path: line.belts.0.speed_mps, range: {from: 0.05, to: 0.25, count: 5}}\n"
         "  - {path: control.compensation, values: [true, false]}\n" +
         extra;
}

std::vector<std::string> IssueTexts(const std::string& file) {
  try {
    LoadSweepSpec(file);
  } catch (const config::ScenarioError& e) {
    std::vector<std::string> out;
    for (const auto& i : e.issues()) out.push_back(i.ToString());
    return out;
  }
  return {};
}

bool AnyContains(const std::vector<std::string>& texts, const std::string& a,
                 const std::string& b = "") {
  return std::any_of(texts.begin(), texts.end(), [&](const std::string& t) {
    return t.find(a) != std::string::npos && t.find(b) != std::string::npos;
  });
}

TEST(SweepSpec, GridCountsRepeatsFastestThenTheLastParameter) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("grid.yaml", BeltSweep("repeats: 2\n")));
  ASSERT_EQ(spec.parameters.size(), 2u);
  // Five evenly spaced speeds, both ends included, as the user means them
  // (0.15, not 0.15000000000000002).
  EXPECT_EQ(spec.parameters[0].values,
            (std::vector<std::string>{"0.05", "0.1", "0.15", "0.2", "0.25"}));
  EXPECT_EQ(spec.parameters[1].values, (std::vector<std::string>{"true", "false"}));
  EXPECT_EQ(RunCount(spec), 5 * 2 * 2);
  // Metrics default to all of the base scenario's.
  EXPECT_FALSE(spec.metrics.empty());
  EXPECT_EQ(spec.scenario, kCrossLine);

  const RunSpec r7 = PlanRun(spec, 7);  // point 3 (speed 0.1, false), repeat 1
  EXPECT_EQ(r7.point, 3);
  EXPECT_EQ(r7.repeat, 1);
  EXPECT_EQ(r7.values, (std::vector<std::string>{"0.1", "false"}));
  const RunSpec last = PlanRun(spec, 19);
  EXPECT_EQ(last.values, (std::vector<std::string>{"0.25", "false"}));
  EXPECT_THROW(PlanRun(spec, 20), std::out_of_range);

  // Every combination exactly once per repeat.
  std::set<std::vector<std::string>> points;
  for (std::int64_t id = 0; id < RunCount(spec); ++id) points.insert(PlanRun(spec, id).values);
  EXPECT_EQ(points.size(), 10u);
}

TEST(SweepSpec, OverridesPutTheSeedFirstAndParametersLast) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("order.yaml", BeltSweep()));
  const RunSpec run = PlanRun(spec, 0);
  EXPECT_EQ(RunOverrides(spec, run),
            (std::vector<std::string>{"seed=" + std::to_string(run.seed), "duration_s=2",
                                      "line.belts.0.speed_mps=0.05", "control.compensation=true"}));
}

TEST(SweepSeeds, CommonSeedsAreSharedAcrossPointsAndIndependentOfPlanningOrder) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("seeds.yaml", BeltSweep("repeats: 3\n")));
  std::vector<RunSpec> forward;
  for (std::int64_t id = 0; id < RunCount(spec); ++id) forward.push_back(PlanRun(spec, id));
  // Planned backwards, one by one, each run is the same.
  for (std::int64_t id = RunCount(spec); id-- > 0;) {
    const RunSpec r = PlanRun(spec, id);
    EXPECT_EQ(r.seed, forward[static_cast<std::size_t>(id)].seed);
    EXPECT_EQ(r.values, forward[static_cast<std::size_t>(id)].values);
  }
  std::set<std::uint64_t> seeds;
  for (const auto& r : forward) {
    seeds.insert(r.seed);
    EXPECT_EQ(r.seed, forward[static_cast<std::size_t>(r.repeat)].seed) << r.id;
    EXPECT_LE(r.seed, static_cast<std::uint64_t>(INT64_MAX));  // a scenario reads int64
  }
  EXPECT_EQ(seeds.size(), 3u);  // one per repeat

  const SweepSpec per_run =
      LoadSweepSpec(WriteFile("seeds2.yaml", BeltSweep("repeats: 3\nseeds: per_run\n")));
  std::set<std::uint64_t> distinct;
  for (std::int64_t id = 0; id < RunCount(per_run); ++id) {
    distinct.insert(PlanRun(per_run, id).seed);
  }
  EXPECT_EQ(distinct.size(), static_cast<std::size_t>(RunCount(per_run)));
  // The sweep seed changes them all.
  const SweepSpec other = LoadSweepSpec(WriteFile("seeds3.yaml", BeltSweep("seed: 2\n")));
  EXPECT_NE(PlanRun(other, 0).seed, PlanRun(spec, 0).seed);
}

TEST(SweepSpec, MonteCarloDrawsAreReproducibleSharedByPointsAndOrderFree) {
  const std::string draws =
      "combine: monte_carlo\nsamples: 400\n"
      "parameters:\n"
      "  - {path: control.compensation, values: [true, false]}\n"
      "  - {path: line.belts.0.speed_mps, random: {distribution: uniform, min: 0.05, max: 0.25}}\n"
      "  - {path: robot.pose.yaw_deg, random: {distribution: normal, mean: 90, std: 5}}\n";
  const std::string head = "scenario: " + kCrossLine + "\nset: {duration_s: 1}\n";
  const SweepSpec spec = LoadSweepSpec(WriteFile("mc.yaml", head + draws));
  EXPECT_EQ(RunCount(spec), 2 * 400);
  double sum = 0, sum_sq = 0, lo = 1, hi = 0;
  for (std::int64_t s = 0; s < 400; ++s) {
    const RunSpec on = PlanRun(spec, s);         // point 0: compensation true
    const RunSpec off = PlanRun(spec, 400 + s);  // point 1: the same draw
    EXPECT_EQ(on.sample, s);
    EXPECT_EQ(on.values[1], off.values[1]);
    EXPECT_EQ(on.values[2], off.values[2]);
    EXPECT_EQ(on.seed, off.seed);  // common random numbers
    const double speed = std::stod(on.values[1]);
    lo = std::min(lo, speed);
    hi = std::max(hi, speed);
    const double yaw = std::stod(on.values[2]);
    sum += yaw;
    sum_sq += yaw * yaw;
  }
  EXPECT_GE(lo, 0.05);
  EXPECT_LT(hi, 0.25);
  // 400 uniform draws cover [0.05, 0.25]: the expected gap at each end is
  // 0.2 / 401 = 5e-4; 1e-2 fails with probability (1 - 0.05)^400 ~ 1e-9.
  EXPECT_LT(lo, 0.06);
  EXPECT_GT(hi, 0.24);
  // Normal(90, 5): the sample mean is within 4 standard errors (4 * 5 / 20).
  const double mean = sum / 400, sd = std::sqrt(sum_sq / 400 - mean * mean);
  EXPECT_NEAR(mean, 90.0, 4 * 5.0 / 20.0);
  EXPECT_NEAR(sd, 5.0, 0.75);  // about 4 standard errors of s (5 / sqrt(800))

  // Reordering the parameters moves no draw: draws follow the path.
  const std::string swapped =
      "combine: monte_carlo\nsamples: 400\n"
      "parameters:\n"
      "  - {path: robot.pose.yaw_deg, random: {distribution: normal, mean: 90, std: 5}}\n"
      "  - {path: line.belts.0.speed_mps, random: {distribution: uniform, min: 0.05, max: 0.25}}\n"
      "  - {path: control.compensation, values: [true, false]}\n";
  const SweepSpec spec2 = LoadSweepSpec(WriteFile("mc2.yaml", head + swapped));
  EXPECT_EQ(PlanRun(spec2, 17).values[0], PlanRun(spec, 17).values[2]);
  EXPECT_EQ(PlanRun(spec2, 17).values[1], PlanRun(spec, 17).values[1]);
}

TEST(SweepSpec, LogUniformDrawsStayInsideTheirBounds) {
  const SweepSpec spec = LoadSweepSpec(WriteFile(
      "logu.yaml", "scenario: " + kCrossLine +
                       "\ncombine: monte_carlo\nsamples: 200\nparameters:\n"
                       "  - {path: line.belts.0.speed_mps, random: {distribution: log_uniform, "
                       "min: 0.01, max: 1}}\n"));
  int below_tenth = 0;
  for (std::int64_t id = 0; id < 200; ++id) {
    const double v = std::stod(PlanRun(spec, id).values[0]);
    EXPECT_GE(v, 0.01);
    EXPECT_LE(v, 1.0);
    below_tenth += v < 0.1 ? 1 : 0;
  }
  // Half of a log-uniform [0.01, 1] lies below 0.1; binomial sd sqrt(50) ~ 7.
  EXPECT_NEAR(below_tenth, 100, 30);
}

TEST(SweepSpec, BadSweepFilesNameFileKeyPathAndWhatWasExpected) {
  const std::string file = WriteFile(
      "bad.yaml", "scenario: " + kCrossLine +
                      "\nrepeatz: 2\n"
                      "metrics: [max_deviaton]\n"
                      "parameters:\n"
                      "  - {path: control.compensaton, values: [true, false]}\n"
                      "  - {path: line.belts.0.speed_mps, range: {from: 0.1, to: 0.2, count: 1}}\n"
                      "  - {path: line.belts.7.speed_mps, values: [0.1]}\n"
                      "  - {path: units.chassis.parameters.muu, values: [0.5]}\n");
  const auto texts = IssueTexts(file);
  ASSERT_FALSE(texts.empty());
  EXPECT_TRUE(AnyContains(texts, file + ":2: repeatz", "unknown key")) << texts[0];
  EXPECT_TRUE(AnyContains(texts, "parameters.1.range.count", "at least 2"));
  // Path problems are found against the base scenario, each at its own key.
  const std::string again =
      WriteFile("bad2.yaml", "scenario: " + kCrossLine +
                                 "\nmetrics: [max_deviaton]\n"
                                 "parameters:\n"
                                 "  - {path: control.compensaton, values: [true, false]}\n"
                                 "  - {path: line.belts.7.speed_mps, values: [0.1]}\n"
                                 "  - {path: units.chassis.parameters.muu, values: [0.5]}\n");
  const auto t2 = IssueTexts(again);
  EXPECT_TRUE(AnyContains(t2, "parameters.0.path", "control.compensation"));  // closest key
  EXPECT_TRUE(AnyContains(t2, "parameters.1.path", "not an item of the list"));
  // A robot file without a units: map takes no unit parameters.
  EXPECT_TRUE(AnyContains(t2, "parameters.2.path", "no key 'units'"));
  EXPECT_TRUE(AnyContains(t2, "metrics.0", "not a metric"));

  EXPECT_TRUE(AnyContains(IssueTexts(WriteFile("nofile.yaml",
                                               "scenario: nowhere.yaml\n"
                                               "parameters: [{path: duration_s, values: [1]}]\n")),
                          "scenario", "refused"));
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("gridrandom.yaml",
                           "scenario: " + kCrossLine +
                               "\nparameters: [{path: duration_s, random: {distribution: uniform, "
                               "min: 1, max: 2}}]\n")),
      "parameters.0.random", "monte_carlo"));
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("twokinds.yaml", "scenario: " + kCrossLine +
                                                "\nparameters: [{path: duration_s, values: [1], "
                                                "range: {from: 1, to: 2, count: 2}}]\n")),
      "parameters.0", "exactly one of"));
  EXPECT_TRUE(AnyContains(IssueTexts(WriteFile("missing.yaml", "parameters: []\n")), "scenario",
                          "missing required key"));
  EXPECT_TRUE(AnyContains(IssueTexts(WriteFile("absent_sweep.yaml", "")), "expected a map"));
  EXPECT_TRUE(AnyContains(IssueTexts("/nonexistent/sweep.yaml"), "cannot read the sweep file"));
}

// Guards the repeatability sweep (paper 2's 20 runs): no parameters but
// repeats, each run its own seed, a reference beside the metrics; refused
// without repeats, or with a reference to a metric it does not collect.
TEST(SweepSpec, RepeatsWithoutParametersAndAReference) {
  const std::string head = "scenario: " + kCrossLine + "\nset: {duration_s: 2}\n";
  const SweepSpec spec = LoadSweepSpec(WriteFile(
      "repeats.yaml", head + "repeats: 3\nseeds: per_run\nmetrics: [max_path_deviation_m]\n"
                             "reference: {title: 'paper 1', metrics: {max_path_deviation_m: "
                             "{label: 'max (m)', max_abs: 0.04}}}\n"));
  EXPECT_EQ(RunCount(spec), 3);
  EXPECT_TRUE(spec.parameters.empty());
  EXPECT_NE(PlanRun(spec, 0).seed, PlanRun(spec, 1).seed);
  ASSERT_EQ(spec.reference.metrics.size(), 1u);
  EXPECT_EQ(spec.reference.title, "paper 1");
  EXPECT_EQ(spec.reference.metrics[0].label, "max (m)");
  EXPECT_EQ(spec.reference.metrics[0].max_abs, 0.04);
  EXPECT_TRUE(std::isnan(spec.reference.metrics[0].std));
  EXPECT_EQ(spec.reference.file, "reference");  // the table files' default name
  EXPECT_EQ(spec.reference.metrics[0].note, "");
  const SweepSpec named = LoadSweepSpec(WriteFile(
      "named.yaml", head + "repeats: 2\nmetrics: [max_path_deviation_m]\n"
                           "reference: {title: t, file: table1, metrics: {max_path_deviation_m: "
                           "{max_abs: 0.04, note: the follower}}}\n"));
  EXPECT_EQ(named.reference.file, "table1");
  EXPECT_EQ(named.reference.metrics[0].note, "the follower");
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("reffile.yaml", head + "repeats: 2\nreference: {title: t, file: "
                                                  "'../x', metrics: {}}\n")),
      "reference.file", "[A-Za-z0-9_-]"));
  EXPECT_TRUE(
      AnyContains(IssueTexts(WriteFile("once.yaml", head)), "parameters", "repeats: N (N >= 2)"));
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile(
          "refbad.yaml", head + "repeats: 2\nreference: {title: t, metrics: {nope: {std: 1}}}\n")),
      "reference.metrics.nope", "not a metric this sweep collects"));
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("refkey.yaml", head + "repeats: 2\nreference: {title: t, metrics: "
                                                 "{max_path_deviation_m: {maxabs: 1}}}\n")),
      "reference.metrics.max_path_deviation_m", "unknown key"));
}

// `run --runs N --set seed=S`: S is the base the N runs' seeds are derived
// from, not a setting every run gets (which made the N runs one run N times).
TEST(SweepSpec, RepeatsOfASetSeedAreDerivedFromIt) {
  const SweepSpec two = RepeatSweepSpec(kCrossLine, {"seed=2", "duration_s=1"}, 3);
  const SweepSpec three = RepeatSweepSpec(kCrossLine, {"seed=3", "duration_s=1"}, 3);
  EXPECT_EQ(two.seed, 2u);
  std::set<std::uint64_t> seeds;
  for (std::int64_t id = 0; id < 3; ++id) {
    const RunSpec run = PlanRun(two, id);
    seeds.insert(run.seed);
    EXPECT_NE(run.seed, PlanRun(three, id).seed);
    const std::vector<std::string> overrides = RunOverrides(two, run);
    EXPECT_EQ(std::count_if(overrides.begin(), overrides.end(),
                            [](const std::string& a) { return a.rfind("seed=", 0) == 0; }),
              1);
    EXPECT_EQ(overrides.front(), "seed=" + std::to_string(run.seed));
  }
  EXPECT_EQ(seeds.size(), 3u);
  // A sweep file says its base seed with seed:, never under set:.
  EXPECT_TRUE(AnyContains(
      IssueTexts(
          WriteFile("setseed.yaml", "scenario: " + kCrossLine + "\nset: {seed: 5}\nrepeats: 2\n")),
      "set.seed", "the sweep's seed:"));
}

TEST(SweepSpec, MalformedPathsDuplicatesAndHugeSweepsAreRefused) {
  const std::string head = "scenario: " + kCrossLine + "\n";
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("empty.yaml", head + "parameters: [{path: '', values: [1]}]\n")),
      "parameters.0.path", "dotted path"));
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("dots.yaml", head + "parameters: [{path: 'a..b', values: [1]}]\n")),
      "parameters.0.path", "dotted path"));
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("setkey.yaml", head + "set: {[a]: 1}\n"
                                                 "parameters: [{path: duration_s, values: "
                                                 "[1]}]\n")),
      ": set:", "dotted paths as keys"));
  // The seed column is the sweep's: the seed is varied by repeats.
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("seed.yaml", head + "parameters: [{path: seed, values: [1, 2]}]\n")),
      "parameters.0.path", "repeats: N"));
  EXPECT_TRUE(
      AnyContains(IssueTexts(WriteFile("twice.yaml", head + "parameters: [{path: duration_s, "
                                                            "values: [1, 2, 1]}]\n")),
                  "parameters.0.values.2", "listed twice"));
  EXPECT_TRUE(
      AnyContains(IssueTexts(WriteFile("flat.yaml", head + "parameters: [{path: duration_s, "
                                                           "range: {from: 1, to: 1, count: "
                                                           "3}}]\n")),
                  "parameters.0.range.to", "!= from"));
  EXPECT_TRUE(AnyContains(
      IssueTexts(
          WriteFile("metric2.yaml", head + "metrics: [max_path_deviation_m, max_path_deviation_m]\n"
                                           "parameters: [{path: duration_s, values: [1]}]\n")),
      "metrics.1", "listed twice"));
  // Bounds that would make NaN or inf values, a value that would break a
  // row in two, and range values that round to the same point.
  EXPECT_TRUE(
      AnyContains(IssueTexts(WriteFile("inf.yaml", head + "parameters: [{path: duration_s, "
                                                          "range: {from: 0, to: .inf, count: "
                                                          "3}}]\n")),
                  "parameters.0.range.to", "expected"));
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("infmc.yaml", head + "combine: monte_carlo\nsamples: 2\n"
                                                "parameters: [{path: duration_s, random: "
                                                "{distribution: uniform, min: 0, max: .inf}}]\n")),
      "parameters.0.random.max", "expected"));
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile("newline.yaml", head + "parameters: [{path: master.algorithm, "
                                                  "values: [jacobi, \"gauss\\nseidel\"]}]\n")),
      "parameters.0.values.1", "line break"));
  EXPECT_TRUE(
      AnyContains(IssueTexts(WriteFile("round.yaml", head + "parameters: [{path: duration_s, "
                                                            "range: {from: 0.1, to: "
                                                            "0.1000000000001, count: 3}}]\n")),
                  "parameters.0.range", "round to the same"));
  // 1000^3 points x 20 repeats: refused before it could overflow or fill
  // the memory with run ids.
  EXPECT_TRUE(AnyContains(
      IssueTexts(WriteFile(
          "huge.yaml",
          head + "repeats: 20\nparameters:\n"
                 "  - {path: duration_s, range: {from: 1, to: 2, count: 1000}}\n"
                 "  - {path: line.belts.0.speed_mps, range: {from: 0, to: 1, count: 1000}}\n"
                 "  - {path: robot.pose.yaw_deg, range: {from: 0, to: 90, count: 1000}}\n")),
      "parameters", "at most 10000000"));
}

TEST(SweepSpec, AWrongKeyInsideAValueFailsOnlyThatRun) {
  // Whole maps as values: the second has a misspelled key. The path exists,
  // so the sweep is accepted whatever the order of the values.
  for (const std::string values :
       {"[{x_m: 0, y_m: -2, yaw_deg: 90}, {x_m: 0, y_m: -2, yaw: 90}]",
        "[{x_m: 0, y_m: -2, yaw: 90}, {x_m: 0, y_m: -2, yaw_deg: 90}]"}) {
    EXPECT_NO_THROW(LoadSweepSpec(
        WriteFile("map.yaml", "scenario: " + kCrossLine +
                                  "\nparameters: [{path: robot.pose, values: " + values + "}]\n")))
        << values;
  }
}

TEST(SweepFingerprint, ChangesWithTheSweepTheScenarioAndTheModelFiles) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("fp.yaml", BeltSweep()));
  const std::string base = SweepFingerprint(spec);
  EXPECT_EQ(base.size(), 64u);  // SHA-256
  EXPECT_EQ(SweepFingerprint(LoadSweepSpec(WriteFile("fp_same.yaml", BeltSweep()))), base);
  EXPECT_NE(SweepFingerprint(LoadSweepSpec(WriteFile("fp_rep.yaml", BeltSweep("repeats: 2\n")))),
            base);
  EXPECT_NE(SweepFingerprint(LoadSweepSpec(WriteFile("fp_seed.yaml", BeltSweep("seed: 3\n")))),
            base);
  // A copy of the model files with one mass changed: the rows would differ.
  const fs::path models =
      fs::path(::testing::TempDir()) / ("sweep_models_" + std::to_string(getpid()));
  fs::remove_all(models);
  fs::copy(LINESIM_SOURCE_DIR "/models", models, fs::copy_options::recursive);
  setenv("LINESIM_MODELS_DIR", models.c_str(), 1);
  const std::string copied =
      SweepFingerprint(LoadSweepSpec(WriteFile("fp_copy.yaml", BeltSweep())));
  { std::ofstream(models / "robots" / "raw3.yaml", std::ios::app) << "\n# edited\n"; }
  const std::string edited =
      SweepFingerprint(LoadSweepSpec(WriteFile("fp_edit.yaml", BeltSweep())));
  unsetenv("LINESIM_MODELS_DIR");
  EXPECT_NE(copied, edited);
}

// cross_line in a folder of its own whose robot, motor and scene are files
// given by path (robot: {model: ./robot.yaml}, the robot's motors
// ./motor.yaml, scene: {model: ./scene.yaml}).
fs::path WritePathModels(const std::string& name) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("sweep_paths_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto replace_all = [](std::string text, const std::string& from, const std::string& to) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
      text.replace(at, from.size(), to);
      at += to.size();
    }
    return text;
  };
  const std::string robot = ReadFile(LINESIM_SOURCE_DIR "/models/robots/raw3.yaml");
  std::ofstream(dir / "robot.yaml")
      << replace_all(robot, "model: maxon_re40_148877", "model: ./motor.yaml");
  fs::copy_file(LINESIM_SOURCE_DIR "/models/motors/maxon_re40_148877.yaml", dir / "motor.yaml");
  fs::copy_file(LINESIM_SOURCE_DIR "/models/scenes/factory_line.yaml", dir / "scene.yaml");
  std::string scenario = ReadFile(kCrossLine);
  scenario = replace_all(scenario, "model: raw3", "model: ./robot.yaml");
  scenario = replace_all(scenario, "{model: factory_line}", "{model: ./scene.yaml}");
  std::ofstream(dir / "scenario.yaml") << scenario;
  std::ofstream(dir / "sweep.yaml") << "scenario: scenario.yaml\nset: {duration_s: 1}\n"
                                       "parameters: [{path: control.compensation, values: [true, "
                                       "false]}]\n";
  return dir;
}

// Guards --resume against rows of two models (issue 37): every file a run
// reads is in the fingerprint by content, whatever its kind and wherever
// it lies, found where the loader reads it rather than listed by kind.
TEST(SweepFingerprint, CoversEveryFileTheRunsReadGivenByPathOrByName) {
  const fs::path dir = WritePathModels("fp");
  const SweepSpec spec = LoadSweepSpec((dir / "sweep.yaml").string());
  for (const char* file : {"scenario.yaml", "robot.yaml", "motor.yaml", "scene.yaml"}) {
    const std::string key = (dir / file).lexically_normal().string();
    ASSERT_TRUE(spec.inputs.count(key)) << key;
    EXPECT_EQ(spec.inputs.at(key).size(), 64u) << key;
  }
  // The sensors' model files, named by the robot file, from models/.
  EXPECT_TRUE(spec.inputs.count((fs::path(LINESIM_SOURCE_DIR) / "models/sensors/sick_s300.yaml")
                                    .lexically_normal()
                                    .string()));
  const std::string before = SweepFingerprint(spec);
  for (const char* file : {"robot.yaml", "motor.yaml", "scene.yaml", "scenario.yaml"}) {
    const std::string text = ReadFile((dir / file).string());
    std::ofstream(dir / file, std::ios::app) << "\n# edited\n";
    EXPECT_NE(SweepFingerprint(LoadSweepSpec((dir / "sweep.yaml").string())), before) << file;
    std::ofstream(dir / file, std::ios::binary) << text;
  }
  EXPECT_EQ(SweepFingerprint(LoadSweepSpec((dir / "sweep.yaml").string())), before);
  // What a run read, recorded by the run itself (a parameter may name
  // other files than the base scenario reads).
  const RunOutcome outcome = ExecuteRun(spec, PlanRun(spec, 0));
  ASSERT_EQ(outcome.status, RunStatus::kOk) << outcome.error;
  EXPECT_EQ(outcome.inputs.at((dir / "robot.yaml").lexically_normal().string()),
            spec.inputs.at((dir / "robot.yaml").lexically_normal().string()));
  EXPECT_TRUE(ChangedInputs(outcome.inputs).empty());
  std::ofstream(dir / "motor.yaml", std::ios::app) << "\n# edited\n";
  const auto changed = ChangedInputs(outcome.inputs);
  ASSERT_EQ(changed.size(), 1u);
  EXPECT_NE(changed[0].find("motor.yaml (its content changed)"), std::string::npos) << changed[0];
}

// Guards a sweep whose file is edited while it runs: a run that read other
// bytes than the rows before it is refused (its row is not written), and a
// run that read a new file adds it to sweep.json before its row.
TEST(ResultsFile, ARunThatReadAnEditedFileIsRefusedAndNewFilesAreNamedFirst) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("inputs.yaml", BeltSweep()));
  const std::string path = WriteFile("inputs_results.csv", "");
  const std::string identity = WriteFile("inputs_sweep.json", "");
  ResultsFile results = ResultsFile::Create(path, spec);
  WriteSweepIdentity(identity, spec, SweepFingerprint(spec), {{"/a.yaml", "1111"}});
  results.TrackInputs(identity, spec, SweepFingerprint(spec), {{"/a.yaml", "1111"}});
  RunOutcome outcome;
  outcome.status = RunStatus::kOk;
  outcome.seed = PlanRun(spec, 0).seed;
  outcome.metrics.assign(spec.metrics.size(), 1.0);
  results.Append(0, FormatRow(PlanRun(spec, 0), outcome), true,
                 {{"/a.yaml", "1111"}, {"/b.yaml", "2222"}});
  ASSERT_TRUE(ReadSweepIdentity(identity));
  EXPECT_EQ(ReadSweepIdentity(identity)->inputs,
            (std::map<std::string, std::string>{{"/a.yaml", "1111"}, {"/b.yaml", "2222"}}));
  const std::string before = ReadFile(path);
  try {
    results.Append(1, FormatRow(PlanRun(spec, 1), outcome), true, {{"/b.yaml", "3333"}});
    ADD_FAILURE() << "a run of another /b.yaml was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/b.yaml changed during the sweep: run 1"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(ReadFile(path), before);
  EXPECT_FALSE(results.HasRow(1));
}

// Every shipped sweep passes the checks made before anything runs: its
// base scenario loads with its fixed settings, each parameter path exists
// and each metric is one the scenario then defines. Named after its file.
TEST(SweepSpec, ShippedSweepsLoad) {
  int count = 0;
  for (const auto& e :
       std::filesystem::directory_iterator(LINESIM_SOURCE_DIR "/scenarios/sweeps")) {
    if (e.path().extension() != ".yaml") continue;
    SCOPED_TRACE(e.path().string());
    const SweepSpec spec = LoadSweepSpec(e.path().string());
    EXPECT_EQ(spec.name, e.path().stem().string());
    ++count;
  }
  EXPECT_GE(count, 7);  // the seven sweeps scenarios/sweeps ships (README)
  const SweepSpec speed =
      LoadSweepSpec(LINESIM_SOURCE_DIR "/scenarios/sweeps/belt_speed_compensation.yaml");
  EXPECT_EQ(speed.scenario, LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml");
}

// Guards the rules a unit declares reaching the sweep file: a unit parameter
// value the unit would refuse fails every run it is in the same way, so the
// sweep is refused before running, at the value's own key, naming the value
// and the rule (dc_motor: resistance > 0, gear_efficiency in (0, 1]).
TEST(SweepSpec, AUnitParameterValueBreakingItsDeclaredRuleIsRefusedAtItsKey) {
  const std::string motor_step = LINESIM_SOURCE_DIR "/scenarios/motor_step.yaml";
  const std::string file = WriteFile(
      "rules.yaml",
      "scenario: " + motor_step +
          "\n"
          "combine: monte_carlo\n"
          "samples: 2\n"
          "parameters:\n"
          "  - {path: units.motors.parameters.resistance, values: [0.3, -1, [0.3, 0]]}\n"
          "  - {path: units.motors.parameters.gear_efficiency.1, range: {from: 0.5, to: 1.5, "
          "count: 3}}\n"
          "  - {path: units.motors.parameters.inductance, random: {distribution: uniform, min: 0, "
          "max: 1e-4}}\n"
          "  - {path: units.supply.parameters.initial, values: [0, 1]}\n");
  const auto texts = IssueTexts(file);
  ASSERT_EQ(texts.size(), 4u) << (texts.empty() ? "" : texts[0]);
  EXPECT_TRUE(
      AnyContains(texts, file + ":5: parameters.0.values.1: units.motors.parameters.resistance: "
                                "must be > 0, got -1 (the rule of unit 'motors' (dc_motor): > 0)"))
      << texts[0];
  EXPECT_TRUE(AnyContains(texts, "parameters.0.values.2.1: units.motors.parameters.resistance.1: ",
                          "must be > 0, got 0"));
  EXPECT_TRUE(
      AnyContains(texts, file + ":6: parameters.1.range.to: ", "must be in (0, 1], got 1.5"));
  EXPECT_TRUE(AnyContains(texts, "parameters.2.random.min: units.motors.parameters.inductance: ",
                          "must be > 0, got 0"));
  // Within the rules (and a unit parameter with no rule): accepted.
  EXPECT_NO_THROW(LoadSweepSpec(WriteFile(
      "rules_ok.yaml",
      "scenario: " + motor_step +
          "\nparameters:\n"
          "  - {path: units.motors.parameters.resistance, values: [0.3, [0.3, 0.5]]}\n"
          "  - {path: units.motors.parameters.gear_efficiency.1, range: {from: 0.5, to: 1, "
          "count: 3}}\n")));
}

TEST(SweepSpec, AnOutOfRangeValueIsARunProblemNotASweepProblem) {
  // A value the scenario refuses fails its own run only: the others may be
  // what the user wants to see.
  EXPECT_NO_THROW(LoadSweepSpec(WriteFile(
      "range.yaml",
      "scenario: " + kCrossLine + "\nparameters: [{path: master.step_s, values: [-1, 0.001]}]\n")));
}

TEST(ResultsCsv, QuotesRoundTrip) {
  const std::vector<std::string> fields{"1", "[1, 2]", "say \"hi\"", "", "a\nb", " pad"};
  const std::string line = JoinCsvLine(fields);
  EXPECT_EQ(line, "1,\"[1, 2]\",\"say \"\"hi\"\"\",,\"a\nb\",\" pad\"\n");
  EXPECT_EQ(SplitCsvLine(line.substr(0, line.size() - 1)), fields);
  EXPECT_FALSE(SplitCsvLine("1,\"open").has_value());
}

// A folder of its own for each test.
std::string FreshDir(const std::string& name) {
  const fs::path p =
      fs::path(::testing::TempDir()) / ("sweep_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

// The rows without the wall_s column (the one before last), the one thing
// that differs between two runs of the same sweep: row_check leaves it out
// (issue 37: it covered wall_s, so it differed too).
std::string WithoutWallTime(const std::string& csv) {
  std::string out;
  std::istringstream in(csv);
  for (std::string line; std::getline(in, line);) {
    const std::size_t check = line.rfind(',');
    const std::size_t wall = line.rfind(',', check - 1);
    out += line.substr(0, wall) + line.substr(check) + "\n";
  }
  return out;
}

std::string RunSweep(const SweepSpec& spec, int jobs, const std::string& dir) {
  ResultsFile results = ResultsFile::Create(dir + "/results.csv", spec);
  std::vector<std::int64_t> ids;
  for (std::int64_t id = 0; id < RunCount(spec); ++id) ids.push_back(id);
  std::atomic<bool> stop{false};
  RunOnThreads(spec, ids, jobs, stop, [&](const RunSpec& run, const RunOutcome& outcome) {
    results.Append(run.id, FormatRow(run, outcome), outcome.status == RunStatus::kOk);
  });
  results.SortByRunId();
  return ReadFile(dir + "/results.csv");
}

TEST(SweepExecutor, OneAndTwoJobsWriteTheSameRowsAndAFailingRunIsIsolated) {
  // A step of 0.003 s does not divide the 20 ms control period: the loader
  // refuses that run; 0.002 s runs. By 6 s the robot is well onto the belt.
  const SweepSpec spec = LoadSweepSpec(
      WriteFile("exec.yaml", "scenario: " + kCrossLine +
                                 "\nset: {duration_s: 6}\n"
                                 "metrics: [max_path_deviation_m]\n"
                                 "parameters:\n"
                                 "  - {path: master.step_s, values: [0.001, 0.003, 0.002]}\n"
                                 "  - {path: control.compensation, values: [true, false]}\n"));
  const std::string one_dir = FreshDir("one");
  const std::string one = RunSweep(spec, 1, one_dir);
  const std::string two = RunSweep(spec, 2, FreshDir("two"));
  EXPECT_EQ(WithoutWallTime(one), WithoutWallTime(two));

  std::istringstream in(one);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(
      header,
      "run_id,master.step_s,control.compensation,seed,max_path_deviation_m,status,error,error_unit,"
      "error_time_s,error_phase,error_variable,error_cause,wall_s,row_check");
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(*SplitCsvLine(line));
  ASSERT_EQ(rows.size(), 6u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i][0], std::to_string(i));  // sorted by run id
    const bool bad = rows[i][1] == "0.003";
    EXPECT_EQ(rows[i][5], bad ? "failed" : "ok") << i;
    EXPECT_EQ(rows[i][4].empty(), bad) << i;
    if (bad) {
      EXPECT_NE(rows[i][6].find("not an integer multiple of the master step 0.003 s"),
                std::string::npos)
          << rows[i][6];
      // The scenario was refused before any unit ran: no unit, no time.
      EXPECT_EQ(rows[i][7], "") << i;
      EXPECT_EQ(rows[i][8], "") << i;
      EXPECT_EQ(rows[i][9], "scenario") << i;
    } else {
      for (int c = 7; c <= 11; ++c) EXPECT_EQ(rows[i][c], "") << i << " " << c;
    }
  }
  // A resumed file counts its failed rows (the two at 0.003 s).
  EXPECT_EQ(ResultsFile::Resume(one_dir + "/results.csv", spec).failed_count(), 2);
  // Compensation on beats off at both good steps (paper 1, Sec. VI-B).
  EXPECT_LT(std::stod(rows[0][4]), std::stod(rows[1][4]));
  EXPECT_LT(std::stod(rows[4][4]), std::stod(rows[5][4]));
}

TEST(SweepExecutor, AStopLeavesNoRowForTheInterruptedRun) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("stop.yaml", BeltSweep()));
  std::vector<std::int64_t> ids;
  for (std::int64_t id = 0; id < RunCount(spec); ++id) ids.push_back(id);
  std::atomic<bool> stop{false};
  std::vector<std::int64_t> done;
  RunOnThreads(spec, ids, 2, stop, [&](const RunSpec& run, const RunOutcome& outcome) {
    // The run stopped on the other thread is never reported.
    EXPECT_NE(outcome.status, RunStatus::kInterrupted) << run.id;
    done.push_back(run.id);
    if (done.size() == 3) stop = true;
  });
  // Three rows; a run that finished on the other thread just before the
  // stop may add a fourth; the stopped one adds none.
  EXPECT_GE(done.size(), 3u);
  EXPECT_LE(done.size(), 4u);
  const RunOutcome o = ExecuteRun(spec, PlanRun(spec, 0), &stop);
  EXPECT_EQ(o.status, RunStatus::kInterrupted);
}

// Guards the structured error of a run that fails while running: the
// outcome and its results row carry the unit, the time of the failing
// step, the phase and the cause beside the whole message. The supply
// steps to 1e308 V at 0.01 s; the motor's di/dt overflows in the step from
// 0.01 s (as in the CLI's numerical-failure test).
TEST(ExecuteRun, AUnitFailureCarriesItsFields) {
  const std::string scenario = WriteFile("blowup_scenario.yaml", R"(duration_s: 0.05
master: {algorithm: jacobi}
units:
  supply:
    type: step_signal
    parameters: {unit: V, steps: [{time_s: 0.01, value: 1.0}]}
  motor:
    type: dc_motor
connections:
  - {from: supply.value, to: motor.voltage}
metrics:
  - {name: peak_current, of: "motor.current[0]", reduce: max_abs}
)");
  const SweepSpec spec = LoadSweepSpec(
      WriteFile("blowup.yaml", "scenario: " + scenario +
                                   "\nparameters: [{path: units.supply.parameters.steps.0.value, "
                                   "values: [1.0, 1.0e308]}]\n"));
  const RunOutcome ok = ExecuteRun(spec, PlanRun(spec, 0));
  ASSERT_EQ(ok.status, RunStatus::kOk) << ok.error;
  const RunOutcome bad = ExecuteRun(spec, PlanRun(spec, 1));
  ASSERT_EQ(bad.status, RunStatus::kFailed);
  EXPECT_EQ(bad.failure.unit, "motor");
  EXPECT_EQ(bad.failure.unit_type, "dc_motor");
  EXPECT_EQ(bad.failure.time, cosim::TimeNs{10'000'000});
  EXPECT_EQ(bad.failure.phase, cosim::RunPhase::kStep);
  EXPECT_NE(bad.failure.cause.find("the derivative of current[0] is inf"), std::string::npos)
      << bad.failure.cause;
  EXPECT_EQ(bad.failure.message, bad.error);
  const auto row = *SplitCsvLine(FormatRow(PlanRun(spec, 1), bad));
  // run_id, value, seed, peak_current, status, error, the 5 fields, wall_s,
  // row_check.
  ASSERT_EQ(row.size(), 13u);
  EXPECT_EQ(row[4], "failed");
  EXPECT_EQ(row[5], bad.error);
  EXPECT_EQ(row[6], "motor");
  EXPECT_EQ(row[7], "0.01");
  EXPECT_EQ(row[8], "step");
  EXPECT_EQ(row[10].substr(0, 20), bad.failure.cause.substr(0, 20));
}

TEST(ResultsFile, ResumeKeepsCompleteRowsAndDropsACutOffLine) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("resume.yaml", BeltSweep()));
  const std::string dir = FreshDir("resume");
  const std::string full = RunSweep(spec, 2, dir);
  // Keep the header and rows 0, 3 and a duplicate of 3; cut row 5 short.
  std::istringstream in(full);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line + "\n");
  const std::string path = dir + "/results.csv";
  std::ofstream(path, std::ios::trunc)
      << lines[0] << lines[4] << lines[1] << lines[4] << lines[6].substr(0, 12);
  ResultsFile resumed = ResultsFile::Resume(path, spec);
  EXPECT_EQ(resumed.row_count(), 2u);
  EXPECT_EQ(resumed.failed_count(), 0);
  EXPECT_TRUE(resumed.HasRow(0));
  EXPECT_TRUE(resumed.HasRow(3));
  EXPECT_FALSE(resumed.HasRow(5));
  EXPECT_EQ(ReadFile(path), lines[0] + lines[1] + lines[4]);

  // The file of a sweep with other metrics (all four against one) is
  // refused, not mixed.
  const SweepSpec other =
      LoadSweepSpec(WriteFile("other.yaml", BeltSweep("metrics: [max_path_deviation_m]\n")));
  std::ofstream(path, std::ios::trunc) << full;
  EXPECT_THROW(ResultsFile::Resume(path, other), std::runtime_error);
  EXPECT_EQ(ReadFile(path), full);  // and left as it was
}

// Guards --resume against rows that are not the plan's (issue: results are
// checked, not trusted): a row with another parameter value, another seed,
// an unknown status or an ok metric that does not parse is dropped and its
// run done again; a well-formed row stays.
TEST(ResultsFile, ResumeDropsRowsThatDoNotMatchThePlan) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("check.yaml", BeltSweep()));
  const std::string dir = FreshDir("check");
  const std::string full = RunSweep(spec, 2, dir);
  std::istringstream in(full);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line + "\n");
  const auto field_replaced = [](std::string line, int field, const std::string& text) {
    std::size_t begin = 0;
    for (int i = 0; i < field; ++i) begin = line.find(',', begin) + 1;
    const std::size_t end = line.find(',', begin);
    return line.replace(begin, end - begin, text);
  };
  // Columns: run_id, speed, compensation, seed, 8 metrics..., status, error,
  // the 5 error fields, wall_s, row_check. Guards issue 24: a metric edited
  // into a finished row (999, a number the plan checks cannot tell from a
  // result) was kept; row_check catches such an edit (not one whose check
  // was recomputed: docs/outputs.md).
  const std::string path = dir + "/results.csv";
  std::ofstream(path, std::ios::trunc)
      << lines[0] << lines[1]                  // run 0 as it was
      << field_replaced(lines[2], 1, "0.3")    // run 1: a value not planned
      << field_replaced(lines[3], 3, "12345")  // run 2: another seed
      << field_replaced(lines[4], 4, "lots")   // run 3: a metric that is no number
      << field_replaced(lines[5], 12, "fine")  // run 4: an unknown status
      << field_replaced(lines[6], 5, "999");   // run 5: an edited metric
  ResultsFile resumed = ResultsFile::Resume(path, spec);
  EXPECT_EQ(resumed.row_count(), 1u);
  EXPECT_TRUE(resumed.HasRow(0));
  EXPECT_EQ(resumed.dropped_count(), 5);
  EXPECT_EQ(ReadFile(path), lines[0] + lines[1]);
}

// Guards the row check's scope (issue 37): it leaves wall_s out, so two
// runs of a row are the same bytes but for wall_s, and it catches what
// happens to a file by accident: a spreadsheet's re-save (CRLF line ends,
// a number rewritten as 1.5E-3), a quote lost. It is no proof against a
// deliberate edit (docs/outputs.md): a row whose check was recomputed
// after an edit is kept, as the docs say.
TEST(ResultsFile, RowCheckLeavesWallTimeOutAndCatchesAccidents) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("rowcheck.yaml", BeltSweep()));
  const RunSpec run = PlanRun(spec, 0);
  RunOutcome outcome;
  outcome.status = RunStatus::kOk;
  outcome.seed = run.seed;
  outcome.metrics.assign(spec.metrics.size(), 0.0015);
  outcome.wall_s = 0.25;
  const std::string a = FormatRow(run, outcome);
  outcome.wall_s = 0.75;
  const std::string b = FormatRow(run, outcome);
  const auto fa = *SplitCsvLine(std::string_view(a).substr(0, a.size() - 1));
  const auto fb = *SplitCsvLine(std::string_view(b).substr(0, b.size() - 1));
  EXPECT_EQ(fa.back(), fb.back());                  // row_check
  EXPECT_NE(fa[fa.size() - 2], fb[fb.size() - 2]);  // wall_s
  EXPECT_EQ(WithoutWallTime(a), WithoutWallTime(b));

  const std::string dir = FreshDir("rowcheck");
  const std::string path = dir + "/results.csv";
  const std::string header = JoinCsvLine(ResultsHeader(spec));
  std::string metric_rewritten = a;
  metric_rewritten.replace(metric_rewritten.find("0.0015"), 6, "1.5E-3");
  std::string crlf = a;
  crlf.insert(crlf.size() - 1, "\r");
  for (const std::string& accident : {crlf, metric_rewritten}) {
    std::ofstream(path, std::ios::trunc | std::ios::binary) << header << accident;
    const ResultsFile resumed = ResultsFile::Resume(path, spec);
    EXPECT_FALSE(resumed.HasRow(0)) << accident;
    EXPECT_EQ(resumed.dropped_count(), 1) << accident;
  }
  // A row as written, or with only its wall time changed, is kept.
  for (const std::string& kept : {a, b}) {
    std::ofstream(path, std::ios::trunc | std::ios::binary) << header << kept;
    EXPECT_TRUE(ResultsFile::Resume(path, spec).HasRow(0)) << kept;
  }
}

TEST(ResultsFile, TableParsesRowsBack) {
  const SweepSpec spec = LoadSweepSpec(WriteFile("table.yaml", BeltSweep()));
  const std::string dir = FreshDir("table");
  RunSweep(spec, 2, dir);
  const SweepTable t = ResultsFile::Resume(dir + "/results.csv", spec).Table(spec);
  ASSERT_EQ(t.rows.size(), 10u);
  EXPECT_EQ(t.parameters,
            (std::vector<std::string>{"line.belts.0.speed_mps", "control.compensation"}));
  EXPECT_EQ(t.metrics.back(), "wall_s");
  EXPECT_EQ(t.levels[1], (std::vector<std::string>{"true", "false"}));
  EXPECT_TRUE(t.grid);
  for (const auto& row : t.rows) {
    EXPECT_TRUE(row.ok) << row.error;
    EXPECT_EQ(row.metrics.size(), t.metrics.size());
    EXPECT_GT(row.metrics.back(), 0.0);
    EXPECT_EQ(row.seed, PlanRun(spec, row.id).seed);
  }
}

TEST(ProgressBar, DrawsInPlaceOnATerminalAndStaysQuietOtherwise) {
  std::ostringstream tty;
  {
    ProgressBar bar(tty, true, 10, 2, 1);  // a resumed sweep: 2 rows, 1 failed
    bar.RunDone(true);
    bar.RunDone(false);
    EXPECT_NE(bar.Text().find("4/10 done, 2 failed"), std::string::npos) << bar.Text();
    EXPECT_NE(bar.Text().find("ETA"), std::string::npos);
    bar.Finish();
    bar.Finish();
  }
  const std::string text = tty.str();
  EXPECT_EQ(text.front(), '\r');  // redrawn in place
  EXPECT_EQ(std::count(text.begin(), text.end(), '\r'), 3);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1);  // one line ended once
  EXPECT_NE(text.find("[############"), std::string::npos);  // 40 % of 30 columns

  std::ostringstream pipe;
  ProgressBar quiet(pipe, false, 10, 0, 0);
  quiet.RunDone(true);
  quiet.Finish();
  EXPECT_TRUE(pipe.str().empty());

  EXPECT_EQ(FormatDuration(0), "0:00");
  EXPECT_EQ(FormatDuration(75.4), "1:15");
  EXPECT_EQ(FormatDuration(3725), "1:02:05");
  EXPECT_EQ(FormatDuration(NAN), "?");
}

}  // namespace
}  // namespace linesim::sweep
