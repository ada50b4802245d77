// `linesim sweep` end to end: the real binary on threads and under mpirun,
// killed and resumed, with real files.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;

const std::string kCrossLine = LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml";

std::string ReadFile(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string Temp(const std::string& name) {
  return (fs::path(::testing::TempDir()) / ("sweepcli_" + std::to_string(getpid()) + "_" + name))
      .string();
}

std::string WriteSweep(const std::string& name, const std::string& text) {
  const std::string path = Temp(name);
  std::ofstream(path) << text;
  return path;
}

// Six short cross_line runs: belt speed x compensation, 3 s each.
std::string SmallSweep(const std::string& name, double duration_s = 3) {
  return WriteSweep(name, "name: small\nscenario: " + kCrossLine +
                              "\nset: {duration_s: " + std::to_string(duration_s) +
                              "}\n"
                              "parameters:\n"
                              "  - {path: line.belts.0.speed_mps, values: [0.05, 0.15, 0.25]}\n"
                              "  - {path: control.compensation, values: [true, false]}\n"
                              "metrics: [max_path_deviation_m]\n");
}

struct Result {
  int status;
  std::string out, err;
};

// Starts `argv` with stdout and stderr into files; returns its pid.
pid_t Spawn(const std::vector<std::string>& argv, const std::string& base) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int out = open((base + ".out").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open((base + ".err").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int in = open("/dev/null", O_RDONLY);
    dup2(in, 0);
    dup2(out, 1);
    dup2(err, 2);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  return pid;
}

int Wait(pid_t pid) {
  int raw = 0;
  waitpid(pid, &raw, 0);
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
}

Result Exec(std::vector<std::string> argv) {
  static int counter = 0;
  const std::string base = Temp("run" + std::to_string(++counter));
  const int status = Wait(Spawn(argv, base));
  return {status, ReadFile(base + ".out"), ReadFile(base + ".err")};
}

Result Sweep(const std::string& file, const std::string& out, std::vector<std::string> extra = {}) {
  std::vector<std::string> argv{LINESIM_CLI, "sweep", file, "--out", out};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return Exec(argv);
}

std::string Fresh(const std::string& name) {
  const std::string p = Temp(name);
  fs::remove_all(p);
  return p;
}

// results.csv without its wall_s column (the one before last; row_check
// leaves it out): the rest must be the same bytes for any jobs, ranks or
// interruptions.
std::string Rows(const std::string& dir) {
  std::string out;
  std::istringstream in(ReadFile(fs::path(dir) / "results.csv"));
  for (std::string line; std::getline(in, line);) {
    const std::size_t check = line.rfind(',');
    const std::size_t wall = line.rfind(',', check - 1);
    out += line.substr(0, wall) + line.substr(check) + "\n";
  }
  return out;
}

std::size_t LineCount(const std::string& file) {
  const std::string text = ReadFile(file);
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

bool IsPng(const fs::path& p) { return ReadFile(p).rfind("\x89PNG", 0) == 0; }

TEST(SweepCli, ThreadsWriteRowsSummaryAndPlotsAndOneOrTwoJobsAgree) {
  const std::string file = SmallSweep("small.yaml");
  const std::string one = Fresh("one"), two = Fresh("two");
  const Result r1 = Sweep(file, one, {"--jobs", "1"});
  ASSERT_EQ(r1.status, 0) << r1.out << r1.err;
  const Result r2 = Sweep(file, two, {"--jobs", "2"});
  ASSERT_EQ(r2.status, 0) << r2.out << r2.err;
  EXPECT_EQ(Rows(one), Rows(two));
  EXPECT_EQ(LineCount(fs::path(one) / "results.csv"), 7u);  // header + 6 runs
  // Not a terminal: no progress bar in the log.
  EXPECT_EQ(r2.err.find("ETA"), std::string::npos) << r2.err;
  EXPECT_NE(r2.out.find("6 runs, 6 ok, 0 failed"), std::string::npos) << r2.out;

  const auto summary = nlohmann::json::parse(ReadFile(fs::path(two) / "summary.json"));
  EXPECT_EQ(summary["runs"], 6);
  EXPECT_EQ(summary["failed"], 0);
  EXPECT_EQ(summary["by_parameter"]["line.belts.0.speed_mps"].size(), 3u);
  std::size_t pngs = 0;
  for (const auto& e : fs::directory_iterator(two)) {
    if (e.path().extension() == ".png") {
      ++pngs;
      EXPECT_TRUE(IsPng(e.path())) << e.path();
    }
  }
  // Two metrics (max_path_deviation_m, wall_s) x two parameters.
  EXPECT_EQ(pngs, 4u);
}

TEST(SweepCli, TwoAndThreeMpiRanksGiveTheThreadedRows) {
  const std::string file = SmallSweep("mpi.yaml");
  const std::string threads = Fresh("threads");
  ASSERT_EQ(Sweep(file, threads, {"--jobs", "2"}).status, 0);
  for (const std::string ranks : {"2", "3"}) {
    const std::string dir = Fresh("mpi" + ranks);
    const Result r = Exec({"mpirun", "--allow-run-as-root", "--oversubscribe", "-n", ranks,
                           LINESIM_CLI, "sweep", file, "--out", dir});
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("MPI worker rank"), std::string::npos) << r.out;
    EXPECT_EQ(Rows(dir), Rows(threads)) << ranks << " ranks";
  }
}

TEST(SweepCli, OneMpiRankRunsAloneAndRanksWithOtherModelFilesAreRefused) {
  const std::string file = SmallSweep("mpi1.yaml", 1);
  const std::string alone = Fresh("mpi_alone");
  const Result r = Exec({"mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "1", LINESIM_CLI,
                         "sweep", file, "--out", alone});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("on rank 0 alone"), std::string::npos) << r.out;
  EXPECT_EQ(LineCount(fs::path(alone) / "results.csv"), 7u);

  // Rank 1 reads a copy of the model files with one line added: its rows
  // could differ, so no rank starts and nothing is written.
  const fs::path models = Temp("models_copy");
  fs::remove_all(models);
  fs::copy(LINESIM_SOURCE_DIR "/models", models, fs::copy_options::recursive);
  std::ofstream(models / "robots" / "raw3.yaml", std::ios::app) << "\n# edited\n";
  const std::string dir = Fresh("mpi_mismatch");
  const Result m = Exec({"mpirun",
                         "--allow-run-as-root",
                         "--oversubscribe",
                         "-n",
                         "1",
                         LINESIM_CLI,
                         "sweep",
                         file,
                         "--out",
                         dir,
                         ":",
                         "-n",
                         "1",
                         "env",
                         "LINESIM_MODELS_DIR=" + models.string(),
                         LINESIM_CLI,
                         "sweep",
                         file,
                         "--out",
                         dir});
  EXPECT_NE(m.status, 0);
  EXPECT_NE(m.err.find("rank 1: linesim: the sweep's settings or a file its base scenario reads "
                       "differs from rank 0's"),
            std::string::npos)
      << m.err;
  EXPECT_FALSE(fs::exists(dir));
}

// Polls until results.csv has `rows` rows (or the process has ended).
void WaitForRows(const std::string& dir, std::size_t rows, pid_t pid) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    if (LineCount(fs::path(dir) / "results.csv") >= rows + 1) return;
    if (waitpid(pid, nullptr, WNOHANG) == pid) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

TEST(SweepCli, AKilledSweepResumesToTheSameFile) {
  // Twenty 6 s runs (~60 ms each) on one job: killed after the third row,
  // about a second before the end.
  const std::string file = WriteSweep(
      "kill.yaml",
      "scenario: " + kCrossLine +
          "\nset: {duration_s: 6}\n"
          "parameters:\n"
          "  - {path: line.belts.0.speed_mps, range: {from: 0.05, to: 0.25, count: 10}}\n"
          "  - {path: control.compensation, values: [true, false]}\n");
  const std::string whole = Fresh("whole");
  ASSERT_EQ(Sweep(file, whole, {"--jobs", "1"}).status, 0);

  const std::string dir = Fresh("killed");
  const pid_t pid =
      Spawn({LINESIM_CLI, "sweep", file, "--out", dir, "--jobs", "1"}, Temp("killed_log"));
  WaitForRows(dir, 3, pid);
  kill(pid, SIGKILL);
  EXPECT_EQ(Wait(pid), 128 + SIGKILL) << "the sweep ended before it could be killed";
  const std::size_t kept = LineCount(fs::path(dir) / "results.csv") - 1;
  EXPECT_GE(kept, 3u);
  EXPECT_LT(kept, 20u);

  // Without --resume the folder is not overwritten.
  const Result refused = Sweep(file, dir);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.err.find("--resume"), std::string::npos) << refused.err;

  const Result resumed = Sweep(file, dir, {"--resume", "--jobs", "2"});
  ASSERT_EQ(resumed.status, 0) << resumed.out << resumed.err;
  EXPECT_NE(resumed.out.find(std::to_string(kept) + " already have rows"), std::string::npos)
      << resumed.out;
  EXPECT_EQ(Rows(dir), Rows(whole));
}

TEST(SweepCli, CtrlCStopsCleanlyAndResumeFinishes) {
  const std::string file = WriteSweep(
      "int.yaml",
      "scenario: " + kCrossLine +
          "\nset: {duration_s: 6}\n"
          "parameters:\n"
          "  - {path: line.belts.0.speed_mps, range: {from: 0.05, to: 0.25, count: 12}}\n"
          "  - {path: control.compensation, values: [true, false]}\n");
  // 24 runs of ~60 ms on one job: Ctrl-C after the second row comes over a
  // second before the end.
  const std::string dir = Fresh("interrupted");
  const std::string log = Temp("int_log");
  const pid_t pid = Spawn({LINESIM_CLI, "sweep", file, "--out", dir, "--jobs", "1"}, log);
  WaitForRows(dir, 2, pid);
  kill(pid, SIGINT);
  EXPECT_EQ(Wait(pid), 130);
  EXPECT_NE(ReadFile(log + ".err").find("--resume"), std::string::npos) << ReadFile(log + ".err");
  // Every line written is a whole row: an interrupted run leaves none.
  const std::string csv = ReadFile(fs::path(dir) / "results.csv");
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');
  EXPECT_EQ(csv.find(",failed,"), std::string::npos) << csv;

  const Result resumed = Sweep(file, dir, {"--resume"});
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  const std::string whole = Fresh("int_whole");
  ASSERT_EQ(Sweep(file, whole).status, 0);
  EXPECT_EQ(Rows(dir), Rows(whole));
}

// Guards --resume against rows of two models (issue 37: a robot file given
// by path was in no fingerprint; edited, a resumed sweep mixed both robots'
// rows with exit 0). The robot files are given by path and varied by the
// sweep, so the second is read only by the runs, never by the base load:
// the runs' own record of what they read must refuse the resume.
TEST(SweepCli, ResumeRefusesWhenAFileARowsRunReadChanged) {
  const fs::path dir = Temp("robots_by_path");
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string robot = ReadFile(LINESIM_SOURCE_DIR "/models/robots/raw3.yaml");
  for (std::size_t at = robot.find("model: maxon_re40_148877"); at != std::string::npos;
       at = robot.find("model: maxon_re40_148877", at + 1)) {
    robot.replace(at, 24, "model: " LINESIM_SOURCE_DIR "/models/motors/maxon_re40_148877.yaml");
  }
  std::ofstream(dir / "a.yaml") << robot;
  std::ofstream(dir / "b.yaml") << robot;
  std::string scenario = ReadFile(kCrossLine);
  scenario.replace(scenario.find("model: raw3"), 11, "model: ./a.yaml");
  std::ofstream(dir / "scenario.yaml") << scenario;
  const std::string file = (dir / "sweep.yaml").string();
  std::ofstream(file) << "scenario: scenario.yaml\nset: {duration_s: 1}\n"
                         "parameters: [{path: robot.model, values: [./a.yaml, ./b.yaml]}]\n";
  const std::string out = Fresh("robots_by_path_out");
  const Result first = Sweep(file, out);
  ASSERT_EQ(first.status, 0) << first.out << first.err;
  const auto identity = nlohmann::json::parse(ReadFile(fs::path(out) / "sweep.json"));
  EXPECT_TRUE(identity["inputs"].contains((dir / "b.yaml").string())) << identity.dump(2);
  const std::string rows = ReadFile(fs::path(out) / "results.csv");

  std::ofstream(dir / "b.yaml", std::ios::app) << "\n# the robot changed\n";
  const Result resumed = Sweep(file, out, {"--resume"});
  EXPECT_EQ(resumed.status, 2) << resumed.out << resumed.err;
  EXPECT_NE(resumed.err.find((dir / "b.yaml").string() + " (its content changed)"),
            std::string::npos)
      << resumed.err;
  EXPECT_EQ(ReadFile(fs::path(out) / "results.csv"), rows);
  // --force starts afresh from the files as they are.
  EXPECT_EQ(Sweep(file, out, {"--force"}).status, 0);
  EXPECT_EQ(Sweep(file, out, {"--resume"}).status, 0);
}

// Guards --resume against a results file that never ends: a link to a
// device (/dev/zero) is refused at once (exit 2, naming the file) instead
// of being read for ever.
TEST(SweepCli, ResumeRefusesAResultsFileThatIsADevice) {
  const std::string file =
      WriteSweep("device.yaml", "scenario: " + kCrossLine +
                                    "\nset: {duration_s: 1}\nparameters:\n"
                                    "  - {path: control.compensation, values: [true, false]}\n");
  const std::string dir = Fresh("device");
  ASSERT_EQ(Sweep(file, dir).status, 0);
  fs::remove(fs::path(dir) / "results.csv");
  fs::create_symlink("/dev/zero", fs::path(dir) / "results.csv");
  const Result r = Sweep(file, dir, {"--resume"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("results.csv is not a regular file"), std::string::npos) << r.err;
}

// `linesim run` under Ctrl-C, as the sweep: it stops at the next
// communication point, keeps the rows recorded so far (whole lines) and
// writes summary.json with status interrupted and the metrics so far; exit
// 130. A 600 s crossing (several seconds of wall time) is stopped once its
// first 100 rows (1 s at 100 Hz) are on disk: well before its 60,001.
TEST(RunCli, CtrlCWritesAnInterruptedSummary) {
  const std::string dir = Fresh("run_interrupted");
  const std::string log = Temp("run_int_log");
  const pid_t pid =
      Spawn({LINESIM_CLI, "run", kCrossLine, "--out", dir, "--set", "duration_s=600"}, log);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline &&
         LineCount(fs::path(dir) / "signals.csv") < 101) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  kill(pid, SIGINT);
  EXPECT_EQ(Wait(pid), 130) << ReadFile(log + ".err");
  const auto summary = nlohmann::json::parse(ReadFile(fs::path(dir) / "summary.json"));
  EXPECT_EQ(summary["status"], "interrupted");
  EXPECT_TRUE(summary["metrics"].contains("max_path_deviation_m")) << summary.dump();
  const std::string csv = ReadFile(fs::path(dir) / "signals.csv");
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');
  EXPECT_LT(LineCount(fs::path(dir) / "signals.csv"), 60001u);
}

// Guards that a run that started always leaves a summary.json (issue:
// hardening): killed outright (SIGKILL: no handler runs), the summary
// written at its start says it failed and why, never a previous run's ok.
TEST(RunCli, AKilledRunLeavesAFailedSummary) {
  const std::string dir = Fresh("run_killed");
  const std::string log = Temp("run_killed_log");
  const pid_t pid =
      Spawn({LINESIM_CLI, "run", kCrossLine, "--out", dir, "--set", "duration_s=600"}, log);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline &&
         LineCount(fs::path(dir) / "signals.csv") < 101) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  kill(pid, SIGKILL);
  Wait(pid);
  const auto summary = nlohmann::json::parse(ReadFile(fs::path(dir) / "summary.json"));
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_NE(summary["errors"][0].get<std::string>().find("did not finish writing its summary"),
            std::string::npos);
}

TEST(SweepCli, AnInterruptedMpiSweepResumesToTheSameFile) {
  const std::string file = WriteSweep(
      "mpiint.yaml", "scenario: " + kCrossLine +
                         "\nset: {duration_s: 6}\n"
                         "parameters:\n"
                         "  - {path: line.belts.0.speed_mps, range: {from: 0.05, to: 0.25, count: "
                         "12}}\n"
                         "  - {path: control.compensation, values: [true, false]}\n");
  const std::string dir = Fresh("mpi_interrupted");
  const pid_t pid = Spawn({"mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "3",
                           LINESIM_CLI, "sweep", file, "--out", dir},
                          Temp("mpi_int_log"));
  WaitForRows(dir, 2, pid);
  // mpirun passes Ctrl-C on to the ranks (when it does so is mpirun's
  // business: the sweep may be further along, or done).
  kill(pid, SIGINT);
  Wait(pid);
  const std::string csv = ReadFile(fs::path(dir) / "results.csv");
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');
  const Result resumed = Exec({"mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "3",
                               LINESIM_CLI, "sweep", file, "--out", dir, "--resume"});
  ASSERT_EQ(resumed.status, 0) << resumed.out << resumed.err;
  const std::string whole = Fresh("mpi_int_whole");
  ASSERT_EQ(Sweep(file, whole, {"--jobs", "2"}).status, 0);
  EXPECT_EQ(Rows(dir), Rows(whole));
}

TEST(SweepCli, AFailedRunIsARowAndTheSweepExitsOne) {
  const std::string file =
      WriteSweep("fail.yaml", "scenario: " + kCrossLine +
                                  "\nset: {duration_s: 1}\n"
                                  "parameters: [{path: master.step_s, values: [0.001, 0.003]}]\n");
  const std::string dir = Fresh("failing");
  const Result r = Sweep(file, dir);
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  const std::string rows = Rows(dir);
  EXPECT_NE(rows.find("\n0,0.001,"), std::string::npos) << rows;
  EXPECT_NE(rows.find(",ok,"), std::string::npos) << rows;
  EXPECT_NE(rows.find("\n1,0.003,"), std::string::npos) << rows;
  EXPECT_NE(rows.find(",failed,"), std::string::npos) << rows;
  EXPECT_TRUE(fs::exists(fs::path(dir) / "summary.json"));
}

TEST(SweepCli, BadInputExitsTwoAndWritesNothing) {
  const std::string bad = WriteSweep("bad.yaml", "scenario: " + kCrossLine +
                                                     "\nparameters: [{path: control.compensaton, "
                                                     "values: [true]}]\n");
  const std::string dir = Fresh("bad");
  const Result r = Sweep(bad, dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(bad + ":2: parameters.0.path"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("control.compensation"), std::string::npos) << r.err;  // the closest key
  EXPECT_FALSE(fs::exists(dir));

  // A value the unit's declared rule refuses (dc_motor: resistance > 0):
  // the sweep file is refused at that value, no run is made.
  const std::string ruled =
      WriteSweep("ruled.yaml",
                 "scenario: " LINESIM_SOURCE_DIR
                 "/scenarios/motor_step.yaml\n"
                 "parameters: [{path: units.motors.parameters.resistance, values: [0.3, -1]}]\n");
  const Result refused_value = Sweep(ruled, dir);
  EXPECT_EQ(refused_value.status, 2);
  EXPECT_NE(
      refused_value.err.find(ruled + ":2: parameters.0.values.1: "
                                     "units.motors.parameters.resistance: must be > 0, got -1"),
      std::string::npos)
      << refused_value.err;
  EXPECT_FALSE(fs::exists(dir));

  EXPECT_EQ(Sweep(Temp("absent.yaml"), dir).status, 2);
  // A folder name the system refuses (over NAME_MAX, 255 bytes on Linux).
  const Result long_name = Sweep(SmallSweep("long.yaml"), Temp(std::string(300, 'a')));
  EXPECT_EQ(long_name.status, 2);
  EXPECT_NE(long_name.err.find("cannot create the output folder"), std::string::npos)
      << long_name.err;
  EXPECT_EQ(Sweep(SmallSweep("jobs.yaml"), dir, {"--jobs", "0"}).status, 2);
  EXPECT_FALSE(fs::exists(dir));

  // A folder of another sweep is not resumed into.
  const std::string file = SmallSweep("first.yaml", 1);
  ASSERT_EQ(Sweep(file, dir).status, 0);
  const Result other = Sweep(SmallSweep("second.yaml", 2), dir, {"--resume"});
  EXPECT_EQ(other.status, 2);
  EXPECT_NE(other.err.find("another sweep"), std::string::npos) << other.err;
  // --force starts it afresh.
  EXPECT_EQ(Sweep(SmallSweep("second.yaml", 2), dir, {"--force"}).status, 0);
}

TEST(SweepCli, ShippedSweepsRunAndShowTheCompensationsBenefit) {
  const std::string belt = Fresh("belt_speed_compensation");
  const Result r = Sweep(LINESIM_SOURCE_DIR "/scenarios/sweeps/belt_speed_compensation.yaml", belt,
                         {"--jobs", "2"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  // Without compensation the cross-track loop e' = -k_cross e + v settles at
  // v / k_cross (k_cross = 1/s in the path follower): 1 s times the belt
  // speed, within the belt's +-10 % speed variation (speed_variation: 0.1 in
  // cross_line.yaml) plus 5 % allowed for the lag of the wheel loops.
  // With it: paper 1, Sec. VI-B, < 4 cm at 0.10 m/s, taken as 0.4 s times
  // the belt speed at the other speeds.
  // The shipped sweep's 2 repeats per point (its file is what is tested);
  // the same sweep with 8 repeats per point, measured once (sensors off,
  // which leaves the control's metrics the same), each run's
  // max_path_deviation_m over the belt speed v: without compensation 0.949
  // to 1.072 (the bound 0.85..1.15; the loop nears v / k by design, so the
  // upper margin is 7 %, not 20), with it at most 0.083 (0.4 asked).
  const auto summary = nlohmann::json::parse(ReadFile(fs::path(belt) / "summary.json"));
  ASSERT_EQ(summary["by_point"].size(), 10u);
  for (const auto& point : summary["by_point"]) {
    const double v = std::stod(point["values"]["line.belts.0.speed_mps"].get<std::string>());
    const bool on = point["values"]["control.compensation"] == "true";
    const double mean = point["metrics"]["max_path_deviation_m"]["mean"];
    if (on) {
      EXPECT_LT(mean, 0.4 * v) << v;
    } else {
      EXPECT_NEAR(mean, v, (0.10 + 0.05) * v) << v;
    }
  }
  const std::string step = Fresh("master_step");
  const Result s =
      Sweep(LINESIM_SOURCE_DIR "/scenarios/sweeps/master_step.yaml", step, {"--jobs", "2"});
  EXPECT_EQ(s.status, 0) << s.out << s.err;
  EXPECT_EQ(LineCount(fs::path(step) / "results.csv"), 13u);
}

}  // namespace
