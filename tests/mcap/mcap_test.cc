#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "loader/scenario.h"
#include "mcap/crc32.h"
#include "mcap/writer.h"
#include "models/scene.h"

namespace linesim::mcap {
namespace {

namespace fs = std::filesystem;

// ---- CRC-32 -------------------------------------------------------------

TEST(Crc32, CheckValueOfTheCatalogue) {
  // "CRC-32/ISO-HDLC" (the CRC of zlib, PNG, MCAP): check = CRC of the
  // nine ASCII digits "123456789" (catalogue of parametrised CRC
  // algorithms, Greg Cook).
  EXPECT_EQ(ComputeCrc32("123456789"), 0xCBF43926u);
  EXPECT_EQ(ComputeCrc32(""), 0u);  // no bytes: the initial value undone by the final XOR
}

TEST(Crc32, RunningEqualsOneCall) {
  Crc32 crc;
  crc.Update("1234");
  crc.Update("");
  crc.Update("56789");
  EXPECT_EQ(crc.Value(), 0xCBF43926u);
}

// ---- Record layout, read back by hand from the specification -----------

std::uint64_t U(const std::string& b, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int k = bytes - 1; k >= 0; --k) {
    v = (v << 8) | static_cast<unsigned char>(b.at(at + static_cast<std::size_t>(k)));
  }
  return v;
}

std::string Str(const std::string& b, std::size_t at) {
  return b.substr(at + 4, static_cast<std::size_t>(U(b, at, 4)));
}

std::string SmallFile(Compression compression, std::size_t chunk_size = 1 << 20) {
  std::ostringstream out;
  WriterOptions options;
  options.compression = compression;
  options.chunk_size = chunk_size;
  Writer w(out, options);
  const auto schema = w.AddSchema("s", "jsonschema", "{}");
  const auto channel = w.AddChannel(schema, "/t", "json", {{"k", "v"}});
  w.WriteMessage(channel, 1000, 1001, "{\"a\":1}");
  w.WriteMessage(channel, 2000, 2000, "{\"a\":2}");
  w.Close();
  return out.str();
}

TEST(Writer, RecordsWhereTheSpecificationPutsThem) {
  const std::string b = SmallFile(Compression::kNone);
  ASSERT_GT(b.size(), 16u);
  EXPECT_EQ(b.substr(0, 8), std::string("\x89MCAP0\r\n", 8));
  EXPECT_EQ(b.substr(b.size() - 8), std::string("\x89MCAP0\r\n", 8));

  // Header: opcode 1, length, profile "", library "linesim".
  std::size_t at = 8;
  ASSERT_EQ(U(b, at, 1), 0x01u);
  EXPECT_EQ(U(b, at + 1, 8), 4u + 0u + 4u + 7u);
  EXPECT_EQ(Str(b, at + 9), "");
  EXPECT_EQ(Str(b, at + 13), "linesim");
  at += 9 + U(b, at + 1, 8);

  // One chunk: start and end times, uncompressed size and CRC, compression
  // "", then its records: schema, channel, two messages.
  const std::size_t chunk_at = at;
  ASSERT_EQ(U(b, at, 1), 0x06u);
  const std::size_t chunk_end = at + 9 + U(b, at + 1, 8);
  EXPECT_EQ(U(b, at + 9, 8), 1000u);
  EXPECT_EQ(U(b, at + 17, 8), 2000u);
  const std::uint64_t size = U(b, at + 25, 8);
  const std::uint32_t crc = static_cast<std::uint32_t>(U(b, at + 33, 4));
  EXPECT_EQ(Str(b, at + 37), "");
  EXPECT_EQ(U(b, at + 41, 8), size);
  const std::string records = b.substr(at + 49, size);
  EXPECT_EQ(at + 49 + size, chunk_end);
  EXPECT_EQ(ComputeCrc32(records), crc);
  std::size_t r = 0;
  ASSERT_EQ(U(records, r, 1), 0x03u);  // schema 1: name, encoding, data
  EXPECT_EQ(U(records, r + 9, 2), 1u);
  EXPECT_EQ(Str(records, r + 11), "s");
  EXPECT_EQ(Str(records, r + 16), "jsonschema");
  EXPECT_EQ(Str(records, r + 30), "{}");
  r += 9 + U(records, r + 1, 8);
  ASSERT_EQ(U(records, r, 1), 0x04u);  // channel 0 on schema 1
  EXPECT_EQ(U(records, r + 9, 2), 0u);
  EXPECT_EQ(U(records, r + 11, 2), 1u);
  EXPECT_EQ(Str(records, r + 13), "/t");
  EXPECT_EQ(Str(records, r + 19), "json");
  EXPECT_EQ(U(records, r + 27, 4), 4u + 1u + 4u + 1u);  // metadata map {"k": "v"}
  r += 9 + U(records, r + 1, 8);
  std::vector<std::size_t> message_at;
  for (int m = 0; m < 2; ++m) {
    ASSERT_EQ(U(records, r, 1), 0x05u);
    message_at.push_back(r);
    EXPECT_EQ(U(records, r + 1, 8), 2u + 4u + 8u + 8u + 7u);
    EXPECT_EQ(U(records, r + 9, 2), 0u);                              // channel
    EXPECT_EQ(U(records, r + 11, 4), static_cast<std::uint64_t>(m));  // sequence
    EXPECT_EQ(U(records, r + 15, 8), m == 0 ? 1000u : 2000u);         // log time
    EXPECT_EQ(U(records, r + 23, 8), m == 0 ? 1001u : 2000u);         // publish time
    EXPECT_EQ(records.substr(r + 31, 7), m == 0 ? "{\"a\":1}" : "{\"a\":2}");
    r += 9 + U(records, r + 1, 8);
  }
  EXPECT_EQ(r, records.size());

  // Its message index: channel 0, (log time, offset in the records) each.
  at = chunk_end;
  const std::size_t index_at = at;
  ASSERT_EQ(U(b, at, 1), 0x07u);
  EXPECT_EQ(U(b, at + 9, 2), 0u);
  ASSERT_EQ(U(b, at + 11, 4), 32u);
  EXPECT_EQ(U(b, at + 15, 8), 1000u);
  EXPECT_EQ(U(b, at + 23, 8), message_at[0]);
  EXPECT_EQ(U(b, at + 31, 8), 2000u);
  EXPECT_EQ(U(b, at + 39, 8), message_at[1]);
  at += 9 + U(b, at + 1, 8);

  // Data end: the CRC of every byte before it.
  ASSERT_EQ(U(b, at, 1), 0x0Fu);
  EXPECT_EQ(U(b, at + 9, 4), ComputeCrc32(std::string_view(b).substr(0, at)));
  at += 9 + U(b, at + 1, 8);
  const std::size_t summary_at = at;

  // Footer: summary start, summary offset start, the summary's CRC.
  const std::size_t footer_at = b.size() - 8 - 29;
  ASSERT_EQ(U(b, footer_at, 1), 0x02u);
  EXPECT_EQ(U(b, footer_at + 1, 8), 20u);
  EXPECT_EQ(U(b, footer_at + 9, 8), summary_at);
  const std::size_t offsets_at = U(b, footer_at + 17, 8);
  EXPECT_EQ(U(b, footer_at + 25, 4),
            ComputeCrc32(std::string_view(b).substr(summary_at, footer_at + 25 - summary_at)));

  // Summary offsets: one per group (schemas, channels, statistics, chunk
  // indexes), each pointing at records of its opcode.
  std::vector<std::uint64_t> groups;
  for (at = offsets_at; at < footer_at; at += 9 + U(b, at + 1, 8)) {
    ASSERT_EQ(U(b, at, 1), 0x0Eu);
    const std::uint64_t op = U(b, at + 9, 1), start = U(b, at + 10, 8), length = U(b, at + 18, 8);
    groups.push_back(op);
    for (std::size_t g = start; g < start + length; g += 9 + U(b, g + 1, 8)) {
      EXPECT_EQ(U(b, g, 1), op);
    }
  }
  EXPECT_EQ(groups, (std::vector<std::uint64_t>{0x03, 0x04, 0x0B, 0x08}));

  // Statistics: 2 messages, 1 schema, 1 channel, 1 chunk, times 1000-2000.
  at = summary_at;
  while (U(b, at, 1) != 0x0Bu) at += 9 + U(b, at + 1, 8);
  EXPECT_EQ(U(b, at + 9, 8), 2u);
  EXPECT_EQ(U(b, at + 17, 2), 1u);
  EXPECT_EQ(U(b, at + 19, 4), 1u);
  EXPECT_EQ(U(b, at + 31, 4), 1u);
  EXPECT_EQ(U(b, at + 35, 8), 1000u);
  EXPECT_EQ(U(b, at + 43, 8), 2000u);
  // Chunk index: where the chunk and its message index are.
  while (U(b, at, 1) != 0x08u) at += 9 + U(b, at + 1, 8);
  EXPECT_EQ(U(b, at + 25, 8), chunk_at);
  EXPECT_EQ(U(b, at + 33, 8), chunk_end - chunk_at);
  ASSERT_EQ(U(b, at + 41, 4), 10u);
  EXPECT_EQ(U(b, at + 45, 2), 0u);
  EXPECT_EQ(U(b, at + 47, 8), index_at);
  EXPECT_EQ(U(b, at + 55, 8), 9u + 2u + 4u + 32u);  // message index bytes
}

TEST(Writer, ZstdChunkNamesItsCompressionAndSizes) {
  const std::string b = SmallFile(Compression::kZstd);
  const std::size_t at = 8 + 9 + 15;
  ASSERT_EQ(U(b, at, 1), 0x06u);
  EXPECT_EQ(Str(b, at + 37), "zstd");
  // The uncompressed size is the plain file's.
  const std::string plain = SmallFile(Compression::kNone);
  EXPECT_EQ(U(b, at + 25, 8), U(plain, at + 25, 8));
  EXPECT_EQ(U(b, at + 33, 4), U(plain, at + 33, 4));  // the CRC is of the uncompressed records
  // A zstd frame: its magic number 0xFD2FB528, little-endian (RFC 8878,
  // 3.1.1).
  EXPECT_EQ(U(b, at + 41 + 4 + 8, 4), 0xFD2FB528u);  // after "zstd" and the records' length
}

TEST(Writer, Lz4ChunkNamesItsCompressionAndSizes) {
  const std::string b = SmallFile(Compression::kLz4);
  const std::size_t at = 8 + 9 + 15;
  ASSERT_EQ(U(b, at, 1), 0x06u);
  EXPECT_EQ(Str(b, at + 37), "lz4");
  const std::string plain = SmallFile(Compression::kNone);
  EXPECT_EQ(U(b, at + 25, 8), U(plain, at + 25, 8));
  EXPECT_EQ(U(b, at + 33, 4), U(plain, at + 33, 4));
  // An LZ4 frame: its magic number 0x184D2204, little-endian (LZ4 frame
  // format description, "General Structure of LZ4 Frame format").
  EXPECT_EQ(U(b, at + 41 + 3 + 8, 4), 0x184D2204u);  // after "lz4" and the records' length
}

TEST(Writer, ChunkClosesAtItsSize) {
  std::ostringstream out;
  WriterOptions options;
  options.chunk_size = 1;  // every message closes its chunk
  Writer w(out, options);
  const auto channel = w.AddChannel(0, "/t", "json");
  for (int k = 0; k < 5; ++k) w.WriteMessage(channel, 10 * k, 10 * k, "{}");
  w.Close();
  EXPECT_EQ(w.chunk_count(), 5u);
  EXPECT_EQ(w.message_count(), 5u);
}

// Guards the metadata record (the run's end, issue 37): written in the
// data section after the chunks, indexed in the summary (a Metadata Index
// pointing at it, in a group of its own) and counted in the statistics.
TEST(Writer, MetadataIsWrittenIndexedAndCounted) {
  std::ostringstream out;
  WriterOptions options;
  options.compression = Compression::kNone;
  Writer w(out, options);
  const auto channel = w.AddChannel(0, "/t", "json");
  w.WriteMessage(channel, 5, 5, "{}");
  w.AddMetadata("linesim.run", {{"status", "interrupted"}, {"end_time_s", "1.5"}});
  w.Close();
  const std::string b = out.str();
  const std::size_t footer_at = b.size() - 8 - 29;
  const std::size_t summary_at = U(b, footer_at + 9, 8);
  // The metadata record: name, then the map (uint32 byte length, pairs).
  std::size_t at = 8;
  while (U(b, at, 1) != 0x0Cu) {
    ASSERT_LT(at, summary_at) << "no metadata record in the data section";
    at += 9 + U(b, at + 1, 8);
  }
  const std::size_t metadata_at = at, metadata_length = 9 + U(b, at + 1, 8);
  EXPECT_EQ(Str(b, at + 9), "linesim.run");
  EXPECT_EQ(U(b, at + 24, 4), (4u + 6u + 4u + 11u) + (4u + 10u + 4u + 3u));
  EXPECT_EQ(Str(b, at + 28), "status");
  EXPECT_EQ(Str(b, at + 38), "interrupted");
  EXPECT_EQ(U(b, metadata_at + metadata_length, 1), 0x0Fu);  // then data end
  // Its index in the summary, and the statistics' count.
  at = summary_at;
  while (U(b, at, 1) != 0x0Du) at += 9 + U(b, at + 1, 8);
  EXPECT_EQ(U(b, at + 9, 8), metadata_at);
  EXPECT_EQ(U(b, at + 17, 8), metadata_length);
  EXPECT_EQ(Str(b, at + 25), "linesim.run");
  at = summary_at;
  while (U(b, at, 1) != 0x0Bu) at += 9 + U(b, at + 1, 8);
  EXPECT_EQ(U(b, at + 27, 4), 1u);  // metadata count
  // A summary offset for the metadata index group.
  bool grouped = false;
  for (at = U(b, footer_at + 17, 8); at < footer_at; at += 9 + U(b, at + 1, 8)) {
    grouped |= U(b, at + 9, 1) == 0x0Du;
  }
  EXPECT_TRUE(grouped);
}

// ---- run.mcap ---------------------------------------------------------------

struct Result {
  int status;
  std::string out, err;
};

std::string ReadFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

Result Shell(const std::string& command) {
  static int counter = 0;
  const std::string base =
      ::testing::TempDir() + "mcap_" + std::to_string(getpid()) + "_" + std::to_string(++counter);
  const int raw =
      std::system((command + " >" + base + ".out 2>" + base + ".err </dev/null").c_str());
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, ReadFile(base + ".out"), ReadFile(base + ".err")};
}

std::string Fresh(const std::string& name) {
  const fs::path p = fs::path(::testing::TempDir()) / (name + "_" + std::to_string(getpid()));
  fs::remove_all(p);
  return p.string();
}

const std::string kCrossLine = LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml";
// 3 s of the crossing: the robot on its way, both car bodies riding, 15
// scans of each LMS151 at 5 Hz, the belt recorded.
const std::string kShort = " --set duration_s=3";

// What the reader's content checks compare with, from the loaded scenario
// (not from the MCAP writer).
nlohmann::json Expectations(const std::string& scenario, const std::vector<std::string>& sets) {
  const loader::Scenario s = loader::LoadScenario(scenario, sets);
  nlohmann::json e;
  e["x"] = s.robot->x_column;
  e["y"] = s.robot->y_column;
  e["yaw"] = s.robot->yaw_column;
  e["compression"] = "lz4";
  // How the run ends (the /log message and the metadata): overwritten by a
  // test that stops it early.
  e["status"] = "ok";
  e["stop_time_s"] = s.duration_s;
  // The rates mcap::RunLogOptions states: scans at 5 Hz, rows at 25 Hz.
  e["scan_period_ns"] = 200'000'000;
  e["signal_period_ns"] = 40'000'000;
  e["beams"] = nlohmann::json::object();
  e["angular_step"] = nlohmann::json::object();
  for (std::size_t u = 0; u < s.system->unit_count(); ++u) {
    const cosim::Unit& unit = s.system->unit(u);
    if (unit.type_name() != "laser_scanner") continue;
    const cosim::VariableTable& v = unit.variables();
    e["beams"][unit.name()] = v.info(*v.Find("ranges")).size;
    e["angular_step"][unit.name()] = v.GetReal(*v.Find("angular_step"));
  }
  e["entities"] = nlohmann::json::array();
  e["belts"] = nlohmann::json::array();
  for (const auto& b : s.scene.belts) e["belts"].push_back("belt/" + b.name);
  for (const auto& o : s.scene.obstacles) e["entities"].push_back("obstacle/" + o.name);
  e["carried"] = nlohmann::json::object();
  for (const auto& c : s.scene.carried) {
    const models::Belt& belt = s.scene.belts.at(static_cast<std::size_t>(c.belt));
    const auto range = models::CarriedTravelRange(belt.area, c.solid);
    if (range[0] > 0.0 || range[1] < 0.0) continue;  // not on its belt at the start
    e["carried"]["carried/" + c.name] = {c.solid.x_m, c.solid.y_m,
                                         s.robot->belt_travel_columns.at(
                                             static_cast<std::size_t>(c.belt)),
                                         belt.area.direction_rad, "belt/" + belt.name};
  }
  return e;
}

TEST(RunMcap, IndependentReaderValidatesAndMatchesTheSignals) {
  const std::string check_dir = LINESIM_MCAP_CHECK_DIR;
  // Not a skip: tools/setup.sh installs the reader; without it this fails.
  ASSERT_TRUE(fs::exists(check_dir + "/node_modules/@mcap/core/package.json") &&
              fs::exists(check_dir + "/node_modules/fzstd/package.json"))
      << "the independent MCAP reader is not installed: run tools/setup.sh (npm ci in "
      << check_dir << ")";
  ASSERT_FALSE(std::string(LINESIM_NODE).empty()) << "node was not found when configuring";

  const std::string dir = Fresh("mcap_cross_line");
  const Result run = Shell(std::string(LINESIM_CLI) + " run " + kCrossLine + kShort +
                           " --mcap --out " + dir);
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("run.mcap"), std::string::npos) << run.out;
  const auto summary = nlohmann::json::parse(ReadFile(dir + "/summary.json"));
  EXPECT_EQ(summary["mcap"]["bytes"].get<std::uint64_t>(), fs::file_size(dir + "/run.mcap"));

  const nlohmann::json expect = Expectations(kCrossLine, {"duration_s=3"});
  ASSERT_GE(expect["beams"].size(), 1u);
  ASSERT_GE(expect["carried"].size(), 1u);
  std::ofstream(dir + "/expect.json") << expect.dump();
  const Result check = Shell(std::string(LINESIM_NODE) + " " + check_dir + "/check_mcap.mjs " +
                             dir + "/run.mcap " + dir + "/signals.csv " + dir + "/expect.json");
  EXPECT_EQ(check.status, 0) << check.out << check.err;
  EXPECT_NE(check.out.find("mcap check: ok"), std::string::npos) << check.out << check.err;
}

// `linesim ARGS` started in the background (its output to files); its pid.
pid_t Start(const std::string& args) {
  const std::string base = ::testing::TempDir() + "mcap_bg_" + std::to_string(getpid());
  const std::string command =
      "exec " + std::string(LINESIM_CLI) + " " + args + " >" + base + ".out 2>" + base + ".err";
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// Waits until `file` holds at least `bytes` (the run is under way), up to
// five minutes; false if it never does.
bool WaitForBytes(const std::string& file, std::uintmax_t bytes) {
  for (int i = 0; i < 3000; ++i) {
    std::error_code ec;
    if (fs::exists(file, ec) && fs::file_size(file, ec) >= bytes) return true;
    usleep(100'000);
  }
  return false;
}

// Guards a cut-short run's log passing for a whole one (issue 37: after
// SIGTERM a valid run.mcap carried no sign of it): it is still valid and
// complete (the independent reader's every check), and says how it ended
// in a last /log message and its "linesim.run" metadata: interrupted, at a
// time before the stop time.
TEST(RunMcap, InterruptedRunIsValidAndSaysSo) {
  const std::string check_dir = LINESIM_MCAP_CHECK_DIR;
  const std::string dir = Fresh("mcap_interrupted");
  // 600 s: far longer than the test waits.
  const pid_t pid = Start("run " + kCrossLine + " --set duration_s=600 --mcap --out " + dir);
  ASSERT_GT(pid, 0);
  const bool running = WaitForBytes(dir + "/signals.csv", 64 * 1024);
  kill(pid, SIGTERM);
  int raw = 0;
  waitpid(pid, &raw, 0);
  ASSERT_TRUE(running) << "the run wrote no signals";
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 130);
  nlohmann::json expect = Expectations(kCrossLine, {"duration_s=600"});
  expect["status"] = "interrupted";
  std::ofstream(dir + "/expect.json") << expect.dump();
  const Result check = Shell(std::string(LINESIM_NODE) + " " + check_dir + "/check_mcap.mjs " +
                             dir + "/run.mcap " + dir + "/signals.csv " + dir + "/expect.json");
  EXPECT_EQ(check.status, 0) << check.out << check.err;
  EXPECT_NE(check.out.find("mcap check: ok"), std::string::npos) << check.out << check.err;
  EXPECT_NE(check.out.find("(interrupted at "), std::string::npos) << check.out;
}

TEST(RunMcap, SameScenarioAndSeedSameBytes) {
  const std::string a = Fresh("mcap_same_a"), b = Fresh("mcap_same_b");
  for (const auto& dir : {a, b}) {
    const Result run = Shell(std::string(LINESIM_CLI) + " run " + kCrossLine +
                             " --set duration_s=1 --mcap --out " + dir);
    ASSERT_EQ(run.status, 0) << run.err;
  }
  const std::string first = ReadFile(a + "/run.mcap");
  EXPECT_GT(first.size(), 1000u);
  EXPECT_TRUE(first == ReadFile(b + "/run.mcap"));
}

TEST(RunMcap, OnlyWithTheFlagAndNoStaleFile) {
  const std::string dir = Fresh("mcap_flag");
  ASSERT_EQ(Shell(std::string(LINESIM_CLI) + " run " + kCrossLine +
                  " --set duration_s=0.1 --mcap --out " + dir)
                .status,
            0);
  ASSERT_TRUE(fs::exists(dir + "/run.mcap"));
  // A later run without --mcap leaves no run.mcap of the earlier one.
  const Result run =
      Shell(std::string(LINESIM_CLI) + " run " + kCrossLine + " --set duration_s=0.1 --out " + dir);
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_FALSE(fs::exists(dir + "/run.mcap"));
  EXPECT_FALSE(nlohmann::json::parse(ReadFile(dir + "/summary.json")).contains("mcap"));
}

TEST(RunMcap, UnwritableFileIsBadInputNamingIt) {
  const std::string dir = Fresh("mcap_unwritable");
  // A non-empty folder where run.mcap would go.
  fs::create_directories(dir + "/run.mcap/inside");
  const Result run = Shell(std::string(LINESIM_CLI) + " run " + kCrossLine +
                           " --set duration_s=0.1 --mcap --out " + dir);
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.err.find(dir + "/run.mcap"), std::string::npos) << run.err;
}

TEST(RunMcap, ComparisonFileIsBadInputNamingIt) {
  // A comparison runs several scenarios: --mcap logs one run.
  const std::string file = LINESIM_SOURCE_DIR "/scenarios/nominal_vs_modified.yaml";
  const Result run =
      Shell(std::string(LINESIM_CLI) + " run " + file + " --mcap --out " + Fresh("mcap_compare"));
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.err.find(file), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("--mcap"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace linesim::mcap
