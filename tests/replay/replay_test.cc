// replay.html (replay/): written by a robot run, self-contained, the same
// bytes for the same run, its data the run's own, and, in a real browser
// (Debian's headless chromium over the DevTools protocol), drawn where the
// run's recorded pose puts the robot, with a play control that advances
// time. Real binary, real files, real browser.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/replay/devtools_pipe.h"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

std::string ReadFile(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string Fresh(const std::string& name) {
  const fs::path p = fs::path(::testing::TempDir()) / (name + "_" + std::to_string(getpid()));
  fs::remove_all(p);
  return p.string();
}

// `linesim ARGS`: its exit status and stderr.
std::pair<int, std::string> Linesim(const std::string& args) {
  static int counter = 0;
  const std::string err = ::testing::TempDir() + "replay_" + std::to_string(getpid()) + "_" +
                          std::to_string(++counter) + ".err";
  const int raw = std::system(
      (std::string(LINESIM_CLI) + " " + args + " >/dev/null 2>" + err + " </dev/null").c_str());
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, ReadFile(err)};
}

const std::string kCrossLine = LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml";

// The JSON inside the page's data element.
Json PageData(const std::string& html) {
  const std::string open = "<script id=\"replay-data\" type=\"application/json\">";
  const std::size_t a = html.find(open);
  if (a == std::string::npos) return Json();
  const std::size_t b = html.find("</script>", a);
  return Json::parse(html.substr(a + open.size(), b - a - open.size()));
}

// signals.csv as columns by header name.
std::map<std::string, std::vector<double>> ReadCsv(const fs::path& p) {
  std::ifstream f(p);
  std::string line;
  std::getline(f, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string cell; std::getline(header, cell, ',');) names.push_back(cell);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(f, line)) {
    std::stringstream row(line);
    std::size_t k = 0;
    for (std::string cell; std::getline(row, cell, ',') && k < names.size(); ++k) {
      columns[names[k]].push_back(std::strtod(cell.c_str(), nullptr));
    }
  }
  return columns;
}

// One 20 s cross_line run (its full duration: the size the issue bounds)
// shared by the tests.
class Replay : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    out_ = new std::string(Fresh("replay_cross_line"));
    const auto [status, err] = Linesim("run " + kCrossLine + " --out " + *out_);
    ASSERT_EQ(status, 0) << err;
  }
  static void TearDownTestSuite() {
    delete out_;
    out_ = nullptr;
  }
  static fs::path Out() { return *out_; }
  static std::string* out_;
};
std::string* Replay::out_ = nullptr;

TEST_F(Replay, OneSelfContainedFileUnderFiveMegabytes) {
  const fs::path page = Out() / "replay.html";
  ASSERT_TRUE(fs::exists(page));
  // Issue 23: a 20 s cross_line replay under 5 MB.
  EXPECT_LT(fs::file_size(page), 5u * 1024u * 1024u);
  const std::string html = ReadFile(page);
  // Nothing fetched: no address of any kind, no external script or style.
  for (const char* outside : {"http:", "https:", "src=", "href=", "@import", "//cdn"}) {
    EXPECT_EQ(html.find(outside), std::string::npos) << outside;
  }
  const auto summary = Json::parse(ReadFile(Out() / "summary.json"));
  EXPECT_EQ(summary["replay"]["file"], "replay.html");
}

TEST_F(Replay, SameBytesForTheSameRunAndNoneWhenAskedNot) {
  const std::string again = Fresh("replay_again");
  ASSERT_EQ(Linesim("run " + kCrossLine + " --out " + again).first, 0);
  EXPECT_TRUE(ReadFile(Out() / "replay.html") == ReadFile(fs::path(again) / "replay.html"));
  // --no-replay: a new run in the same folder removes the old page.
  ASSERT_EQ(Linesim("run " + kCrossLine + " --out " + again + " --no-replay").first, 0);
  EXPECT_FALSE(fs::exists(fs::path(again) / "replay.html"));
  EXPECT_FALSE(Json::parse(ReadFile(fs::path(again) / "summary.json")).contains("replay"));
  // A value that is no yes or no: a usage error, exit 2, naming the flag.
  const auto [status, err] = Linesim("run " + kCrossLine + " --out " + again + " --no-replay=maybe");
  EXPECT_EQ(status, 2);
  EXPECT_NE(err.find("no-replay"), std::string::npos) << err;
}

TEST_F(Replay, DataIsTheRunsOwnAtTheStatedRates) {
  const Json d = PageData(ReadFile(Out() / "replay.html"));
  ASSERT_TRUE(d.is_object());
  const auto csv = ReadCsv(Out() / "signals.csv");
  // Frames every 20 ms (50 Hz) from 0 to 20 s: 1001.
  ASSERT_EQ(d["t"].size(), 1001u);
  EXPECT_EQ(d["rates"]["frame_hz"], 50);
  EXPECT_EQ(d["rates"]["scan_hz"], 10);
  // signals.csv has a row every 10 ms (the robot expansion's 100 Hz): the
  // frame at 20 k ms is row 2 k. Positions are written to 0.1 mm and the
  // yaw to 1e-5 rad, so they differ by at most half of that.
  const auto& time = csv.at("time");
  for (std::size_t k = 0; k < d["t"].size(); k += 50) {
    const std::size_t row = 2 * k;
    ASSERT_LT(row, time.size());
    EXPECT_NEAR(d["t"][k].get<double>(), time[row], 1e-9);
    EXPECT_NEAR(d["x"][k].get<double>(), csv.at("chassis.position[0]")[row], 0.5e-4 + 1e-12);
    EXPECT_NEAR(d["y"][k].get<double>(), csv.at("chassis.position[1]")[row], 0.5e-4 + 1e-12);
    EXPECT_NEAR(d["yaw"][k].get<double>(), csv.at("chassis.yaw")[row], 0.5e-5 + 1e-12);
    EXPECT_NEAR(d["plots"][0]["curves"][0]["values"][k].get<double>(),
                csv.at("deviation.deviation")[row], 0.5e-5 + 1e-12);
  }
  // The scene's line (scenarios/cross_line.yaml: one belt 20 x 2 m) and the
  // path from (0, -2) to (0, 2).
  ASSERT_EQ(d["belts"].size(), 1u);
  EXPECT_EQ(d["belts"][0]["length"], 20);
  EXPECT_EQ(d["belts"][0]["width"], 2);
  EXPECT_EQ(d["path"], Json::parse("[[0,-2],[0,2]]"));
  // Scans: every laser keeps the first scan starting at or after each
  // 100 ms mark, so consecutive kept scans are 100 ms apart within one scan
  // period (the S300's scan cycle of 40 ms: SICK operating instructions 8010948, as
  // models/sensors/sick_s300.yaml gives it).
  ASSERT_FALSE(d["lasers"].empty());
  for (const auto& laser : d["lasers"]) {
    const auto& scans = laser["scans"];
    ASSERT_GT(scans.size(), 150u) << laser["name"];
    for (std::size_t i = 1; i < scans.size(); ++i) {
      const double gap = scans[i]["t"].get<double>() - scans[i - 1]["t"].get<double>();
      EXPECT_GT(gap, 0.1 - 0.04 - 1e-9) << laser["name"] << " scan " << i;
      EXPECT_LT(gap, 0.1 + 0.04 + 1e-9) << laser["name"] << " scan " << i;
    }
  }
}

// The browser: Debian's chromium (tools/setup.sh installs it). Missing, the
// test fails: the replay is not checked without it.
const std::string kChromium = "/usr/bin/chromium";

TEST_F(Replay, ChromiumDrawsTheRobotAtItsRecordedPoseAndPlays) {
  ASSERT_TRUE(fs::exists(kChromium)) << kChromium << " is missing: run tools/setup.sh";
  const fs::path page = fs::absolute(Out() / "replay.html");
  const std::string profile = Fresh("replay_chromium_profile");
  linesim::replay_test::DevToolsPipe browser(kChromium, profile);
  const std::string s = browser.OpenPage();
  browser.Call("Runtime.enable", {}, s);
  browser.Call("Log.enable", {}, s);
  browser.Call("Page.enable", {}, s);
  browser.Call("Emulation.setDeviceMetricsOverride",
               {{"width", 1400}, {"height", 900}, {"deviceScaleFactor", 1}, {"mobile", false}}, s);
  browser.Call("Page.navigate", {{"url", "file://" + page.string()}}, s);
  browser.WaitFor("Page.loadEventFired", s);
  ASSERT_TRUE(browser.Evaluate(s, "typeof window.linesimReplay === 'object'").get<bool>());

  // At t = 5 s (a frame: a multiple of 20 ms, and row 500 of signals.csv),
  // with the view set to a known centre and scale, the outline's edges are
  // where the recorded pose maps them: pixel = (W/2 + (x - cx) s,
  // H/2 - (y - cy) s), y up. The body is the Rob@Work 3's 1.03 x 0.57 m
  // (paper 1, Table I).
  const auto csv = ReadCsv(Out() / "signals.csv");
  const std::size_t row = 500;
  ASSERT_NEAR(csv.at("time")[row], 5.0, 1e-9);
  const double x = csv.at("chassis.position[0]")[row], y = csv.at("chassis.position[1]")[row],
               yaw = csv.at("chassis.yaw")[row];
  const double cx = x + 0.3, cy = y - 0.2, scale = 150.0;
  const Json v = browser.Evaluate(
      s, "linesimReplay.setTime(5); linesimReplay.setView(" + std::to_string(cx) + "," +
             std::to_string(cy) + "," + std::to_string(scale) + "); linesimReplay.view()");
  const double w = v["width"].get<double>(), h = v["height"].get<double>();
  ASSERT_GT(w, 400);
  ASSERT_GT(h, 300);
  const auto pixel = [&](double along, double across) {
    const double px = x + along * std::cos(yaw) - across * std::sin(yaw);
    const double py = y + along * std::sin(yaw) + across * std::cos(yaw);
    return std::array<long, 2>{std::lround(w / 2 + (px - cx) * scale),
                               std::lround(h / 2 - (py - cy) * scale)};
  };
  // Whether the outline's colour (#ff00ff, used by nothing else) is within
  // 2 px of a pixel.
  const auto magenta_near = [&](std::array<long, 2> p) {
    const std::string js =
        "(() => { const c = document.getElementById('view').getContext('2d');"
        " const d = c.getImageData(" +
        std::to_string(p[0] - 2) + "," + std::to_string(p[1] - 2) +
        ",5,5).data; for (let i = 0; i < d.length; i += 4)"
        " if (d[i] === 255 && d[i + 1] === 0 && d[i + 2] === 255) return true; return false; })()";
    return browser.Evaluate(s, js).get<bool>();
  };
  const double half_l = 1.03 / 2, half_w = 0.57 / 2, outside = 0.08;
  const std::array<std::array<double, 2>, 4> edges = {
      {{half_l, 0.0}, {-half_l, 0.0}, {0.0, half_w}, {0.0, -half_w}}};
  for (const auto& e : edges) {
    EXPECT_TRUE(magenta_near(pixel(e[0], e[1]))) << "edge at " << e[0] << ", " << e[1];
    // 8 cm (12 px) outside the edge: no outline there.
    const double n = std::hypot(e[0], e[1]);
    EXPECT_FALSE(magenta_near(pixel(e[0] + outside * e[0] / n, e[1] + outside * e[1] / n)))
        << "outside the edge at " << e[0] << ", " << e[1];
  }
  // The heading, a line from the centre to 0.4 of the length forward: there
  // at 0.3 forward, not at 0.3 back (a wrong yaw's sign or offset shows).
  EXPECT_TRUE(magenta_near(pixel(0.3 * 1.03, 0.0)));
  EXPECT_FALSE(magenta_near(pixel(-0.3 * 1.03, 0.0)));

  // Play: from t = 0 the page's time moves on by itself (the promise waits
  // for it, up to 20 s of the browser's time, and returns the time seen).
  const double played =
      browser
          .Evaluate(s,
                    "linesimReplay.setTime(0); document.getElementById('play').click();"
                    " new Promise((done) => { const t0 = performance.now();"
                    " const look = () => { if (linesimReplay.time() > 0.05 ||"
                    " performance.now() - t0 > 20000) { done(linesimReplay.time()); return; }"
                    " requestAnimationFrame(look); }; look(); })")
          .get<double>();
  EXPECT_GT(played, 0.05);
  EXPECT_TRUE(browser.Evaluate(s, "linesimReplay.playing()").get<bool>());
  // The slider follows the time.
  EXPECT_GT(browser.Evaluate(s, "Number(document.getElementById('slider').value)").get<double>(),
            0.0);
  browser.Evaluate(s, "document.getElementById('play').click(); 0");
  EXPECT_FALSE(browser.Evaluate(s, "linesimReplay.playing()").get<bool>());

  // No error on the console, no exception, nothing failed to load.
  for (const auto& e : browser.events()) {
    const std::string method = e.value("method", "");
    EXPECT_NE(method, "Runtime.exceptionThrown") << e.dump();
    if (method == "Runtime.consoleAPICalled") {
      EXPECT_NE(e["params"].value("type", ""), "error") << e.dump();
      EXPECT_NE(e["params"].value("type", ""), "assert") << e.dump();
    }
    if (method == "Log.entryAdded") {
      EXPECT_NE(e["params"]["entry"].value("level", ""), "error") << e.dump();
    }
  }
}

// ---- Texts from the scenario are text, never code ------------------------

// A piece of markup that, if it ever ran, would leave a trace: the global
// linesimPwned set to `tag`, and an error on the console.
std::string Hostile(int kind, const std::string& tag) {
  const std::string trace = "window.linesimPwned='" + tag + "';console.error('pwned " + tag + "')";
  switch (kind % 6) {
    case 0:
      return "<img src=x onerror=\"" + trace + "\"> " + tag;
    case 1:
      return "</script><script>" + trace + "</script> " + tag;
    case 2:
      return "<svg onload=\"" + trace + "\"></svg> " + tag;
    case 3:
      return "\"'><iframe srcdoc=\"&lt;script&gt;parent." + trace + "&lt;/script&gt;\"></iframe> " +
             tag;
    case 4:
      return "<!--<script>" + trace + "</script>--> &amp; &lt;b&gt; " + tag;
    default:
      return "<style>body{display:none}</style><b onmouseover=\"" + trace + "\">" + tag +
             "</b>\u2028 \xc3\xa4";
  }
}

// A robot scenario whose every free text is hostile: its name and
// description, the scene's surfaces, belt, obstacle, carried body and
// terrain piece (robot, worker, unit, variable and metric names are
// identifiers: letters, digits, _).
struct HostileTexts {
  std::string name = Hostile(0, "name"), description = Hostile(1, "description");
  std::string floor = Hostile(2, "floor"), belt_surface = Hostile(3, "belt surface");
  std::string belt = Hostile(4, "belt"), obstacle = Hostile(5, "obstacle");
  std::string carried = Hostile(0, "carried"), terrain = Hostile(1, "terrain");
};

std::string HostileScenario(const HostileTexts& h) {
  // JSON strings are YAML double-quoted scalars.
  const auto q = [](const std::string& s) { return Json(s).dump(); };
  const std::string file = ::testing::TempDir() + "hostile_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(file) << "name: " << q(h.name) << "\ndescription: " << q(h.description) << R"(
duration_s: 0.5
seed: 1
master: {algorithm: gauss_seidel, step_s: 0.005}
robot:
  model: raw3
  pose: {x_m: 0.0, y_m: -2.0, yaw_deg: 90}
scene:
  surfaces:
    - {name: )" << q(h.floor)
                      << R"(, friction: 0.8, texture_contrast: 0.2, illumination_lux: 500}
    - {name: )" << q(h.belt_surface)
                      << R"(, friction: 0.8, texture_contrast: 0.05, illumination_lux: 500}
  floor: {min_x_m: -15.0, max_x_m: 15.0, min_y_m: -10.0, max_y_m: 10.0, surface: )"
                      << q(h.floor) << R"(}
  belts:
    - {name: )" << q(h.belt)
                      << ", surface: " << q(h.belt_surface) << R"(, center_x_m: 0.0,
       center_y_m: 0.0, length_m: 20.0, width_m: 2.0, direction_deg: 0, speed_mps: 0.1,
       schedule: [{time_s: 0, on: true}]}
  obstacles:
    - {name: )" << q(h.obstacle)
                      << R"(, kind: cart,
       box: {x_m: 5.0, y_m: -4.0, yaw_deg: 0, length_m: 1.2, width_m: 0.8, height_m: 1.0}}
  carried:
    - {name: )" << q(h.carried)
                      << ", belt: " << q(h.belt) << R"(,
       box: {x_m: 6.0, y_m: 0.0, yaw_deg: 0, length_m: 4.6, width_m: 1.8, height_m: 1.2, bottom_m: 0.3},
       skids: {width_m: 0.1, gauge_m: 1.2}}
  terrain:
    - {name: )" << q(h.terrain)
                      << R"(, center_m: [8.0, -6.0, 0.05], size_m: [2.0, 1.0, 0.1],
       surface: )" << q(h.floor)
                      << R"(}
control: {compensation: true, period_s: 0.02}
task: {type: path, waypoints: [[0.0, -2.0], [0.0, 2.0]], speed_mps: 0.3}
sensors: {default: true}
sensing: {surface_velocity: ground_truth}
localization: {source: ground_truth}
)";
  return file;
}

// A page in Debian's headless chromium, at 1400 x 900, from the disk.
std::string OpenPage(linesim::replay_test::DevToolsPipe& browser, const fs::path& page) {
  const std::string s = browser.OpenPage();
  browser.Call("Runtime.enable", {}, s);
  browser.Call("Log.enable", {}, s);
  browser.Call("Page.enable", {}, s);
  browser.Call("Emulation.setDeviceMetricsOverride",
               {{"width", 1400}, {"height", 900}, {"deviceScaleFactor", 1}, {"mobile", false}}, s);
  browser.Call("Page.navigate", {{"url", "file://" + fs::absolute(page).string()}}, s);
  browser.WaitFor("Page.loadEventFired", s);
  return s;
}

// Every console message, exception and log entry so far (the policy's
// refusals are log entries of level error).
std::vector<std::string> Complaints(const linesim::replay_test::DevToolsPipe& browser) {
  std::vector<std::string> out;
  for (const auto& e : browser.events()) {
    const std::string method = e.value("method", "");
    if (method == "Runtime.exceptionThrown" || method == "Runtime.consoleAPICalled" ||
        (method == "Log.entryAdded" && e["params"]["entry"].value("level", "") == "error")) {
      out.push_back(e.dump());
    }
  }
  return out;
}

// Guards against a page that runs a scenario's text as code (issue 37: the
// legend was built with innerHTML, and a surface named <img src=x
// onerror=...> ran its handler in Chromium): every text the page shows is
// a text node, the canvas's text or an attribute set as text; no handler
// of any of them runs, nothing of them becomes an element, and each is
// shown as written.
TEST(ReplayHostileTexts, AreShownAsTextAndNothingOfThemRuns) {
  ASSERT_TRUE(fs::exists(kChromium)) << kChromium << " is missing: run tools/setup.sh";
  const HostileTexts h;
  const std::string out = Fresh("replay_hostile");
  const auto [status, err] = Linesim("run " + HostileScenario(h) + " --out " + out);
  ASSERT_EQ(status, 0) << err;
  const fs::path page = fs::path(out) / "replay.html";
  const std::string html = ReadFile(page);
  // In the file: the texts only as JSON strings, their '<' escaped.
  for (const std::string* text : {&h.name, &h.description, &h.floor, &h.belt, &h.obstacle}) {
    EXPECT_EQ(html.find(*text), std::string::npos) << *text;
  }

  linesim::replay_test::DevToolsPipe browser(kChromium, Fresh("replay_hostile_profile"));
  const std::string s = OpenPage(browser, page);
  ASSERT_TRUE(browser.Evaluate(s, "typeof window.linesimReplay === 'object'").get<bool>())
      << "the page's own script did not run (its policy's hash?)";
  // The canvas's texts, recorded while the page draws again at 0.3 s.
  browser.Evaluate(s,
                   "window.drawn = []; const fill = CanvasRenderingContext2D.prototype.fillText;"
                   " CanvasRenderingContext2D.prototype.fillText = function (t, ...rest) {"
                   " window.drawn.push(String(t)); return fill.call(this, t, ...rest); };"
                   " linesimReplay.setTime(0.3); 0");
  const Json shown =
      browser.Evaluate(s,
                       "({ pwned: typeof window.linesimPwned, title: document.title,"
                       " heading: document.getElementById('title').textContent,"
                       " tooltip: document.getElementById('title').title,"
                       " legend: document.getElementById('legend').textContent,"
                       " elements: document.querySelectorAll('img, svg, iframe, b').length,"
                       " styles: document.querySelectorAll('style').length,"
                       " scripts: document.querySelectorAll('script').length,"
                       " drawn: window.drawn, data: linesimReplay.data })");
  EXPECT_EQ(shown["pwned"], "undefined");
  EXPECT_EQ(shown["title"], "linesim replay: " + h.name);
  EXPECT_EQ(shown["heading"], "linesim replay: " + h.name);
  EXPECT_EQ(shown["tooltip"], h.description);
  const std::string legend = shown["legend"].get<std::string>();
  EXPECT_NE(legend.find(h.floor), std::string::npos) << legend;
  EXPECT_NE(legend.find(h.belt_surface), std::string::npos) << legend;
  EXPECT_EQ(shown["elements"], 0);
  EXPECT_EQ(shown["styles"], 1);   // the page's own
  EXPECT_EQ(shown["scripts"], 2);  // its data and its code
  bool belt_drawn = false;
  for (const auto& t : shown["drawn"]) belt_drawn |= t.get<std::string>().starts_with(h.belt);
  EXPECT_TRUE(belt_drawn) << shown["drawn"].dump();
  // The texts the page keeps without showing them, as written.
  const Json& d = shown["data"];
  EXPECT_EQ(d["obstacles"][0]["name"], h.obstacle);
  EXPECT_EQ(d["carried"][0]["name"], h.carried);
  EXPECT_EQ(d["terrain"][0]["name"], h.terrain);
  EXPECT_EQ(d["belts"][0]["name"], h.belt);
  // Nothing on the console: no handler's error, no refusal of the policy
  // (nothing tried to run), no exception.
  EXPECT_TRUE(Complaints(browser).empty()) << Complaints(browser).front();

  // The policy stands behind it: markup put in by a script later (as the
  // old legend did) gets no handler run; the browser reports the refusal.
  const Json probe = browser.Evaluate(
      s,
      "new Promise((done) => { let refused = 0;"
      " document.addEventListener('securitypolicyviolation', () => { refused++; });"
      " document.body.insertAdjacentHTML('beforeend',"
      " '<img src=\"x\" onerror=\"window.policyProbe = 1\"><div onclick=\"window.policyProbe = 2\"'"
      " + ' id=\"probe\"></div>');"
      " document.getElementById('probe').click();"
      " setTimeout(() => done({ ran: typeof window.policyProbe, refused }), 500); })");
  EXPECT_EQ(probe["ran"], "undefined");
  EXPECT_GE(probe["refused"].get<int>(), 1);
}

// ---- A run cut short says so ---------------------------------------------

// Guards a replay of a cut-short run passing for a whole one (issue 37:
// after SIGTERM replay.html carried no sign of it): its data say
// interrupted, at the time reached of the time meant, and the page says so
// above everything, in words.
TEST(ReplayInterrupted, ThePageSaysTheRunWasCutShort) {
  ASSERT_TRUE(fs::exists(kChromium)) << kChromium << " is missing: run tools/setup.sh";
  const std::string out = Fresh("replay_interrupted");
  const std::string base = ::testing::TempDir() + "replay_bg_" + std::to_string(getpid());
  // 600 s: far longer than the test waits.
  const std::string command = "exec " + std::string(LINESIM_CLI) + " run " + kCrossLine +
                              " --set duration_s=600 --out " + out + " >" + base + ".out 2>" +
                              base + ".err";
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  ASSERT_GT(pid, 0);
  // Under way once signals.csv holds some rows (up to five minutes).
  bool running = false;
  for (int i = 0; i < 3000 && !running; ++i) {
    std::error_code ec;
    running = fs::file_size(fs::path(out) / "signals.csv", ec) >= 64 * 1024 && !ec;
    if (!running) usleep(100'000);
  }
  kill(pid, SIGTERM);
  int raw = 0;
  waitpid(pid, &raw, 0);
  ASSERT_TRUE(running) << "the run wrote no signals";
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 130);

  const fs::path page = fs::path(out) / "replay.html";
  const Json d = PageData(ReadFile(page));
  ASSERT_TRUE(d.is_object());
  EXPECT_EQ(d["outcome"]["status"], "interrupted");
  EXPECT_EQ(d["outcome"]["stop_s"], 600);
  const double end = d["outcome"]["end_s"].get<double>();
  EXPECT_GT(end, 0.0);
  EXPECT_LT(end, 600.0);
  EXPECT_NEAR(end, d["t"].back().get<double>(), 0.02 + 1e-9);  // the last frame, 20 ms apart
  EXPECT_NE(d["outcome"]["message"].get<std::string>().find("SIGTERM"), std::string::npos);

  linesim::replay_test::DevToolsPipe browser(kChromium, Fresh("replay_interrupted_profile"));
  const std::string s = OpenPage(browser, page);
  const Json banner = browser.Evaluate(
      s,
      "({ text: document.getElementById('outcome').textContent,"
      " shown: getComputedStyle(document.getElementById('outcome')).display !== 'none' })");
  EXPECT_TRUE(banner["shown"].get<bool>());
  EXPECT_EQ(banner["text"].get<std::string>().rfind("INTERRUPTED at ", 0), 0u) << banner.dump();
  EXPECT_NE(banner["text"].get<std::string>().find("of 600 s"), std::string::npos) << banner.dump();
  EXPECT_TRUE(Complaints(browser).empty()) << Complaints(browser).front();
}

// Guards the other side: a run that reached its end says ok, at its stop
// time, with nothing to explain (the page shows no banner for it).
TEST_F(Replay, AWholeRunSaysItEndedOk) {
  const Json d = PageData(ReadFile(Out() / "replay.html"));
  EXPECT_EQ(d["outcome"]["status"], "ok");
  EXPECT_EQ(d["outcome"]["end_s"], 20);
  EXPECT_EQ(d["outcome"]["stop_s"], 20);
  EXPECT_EQ(d["outcome"]["message"], "");
}

}  // namespace
