// replay.html's data (replay/replay_data.h): the input is the page's data
// JSON as a run writes it (seeded from real runs' pages), read into a
// ReplayData (what the recorder fills during a run) and written out again
// as the page. Optionally, after a NUL byte, raw bytes (not necessarily
// UTF-8) that become the texts of the scenario's name, description,
// surfaces, belts, obstacles and plot labels, as a scenario file could
// give them. The page's contract, checked for every input:
//   - the data's text holds no '<': nothing in it can end the <script>
//     element it sits in, or open a comment or another script;
//   - it is valid UTF-8 JSON (a strict reader parses it);
//   - every text comes back as given (as U+FFFD where it was not UTF-8);
//   - every number comes back within half its written precision (positions
//     0.1 mm, angles 1e-5 rad, signals 1e-5, times 1e-6 s, ranges 1 mm), a
//     number too large for that exactly, one not finite as null;
//   - the same data give the same bytes.
// A broken contract aborts (a finding); an input that is not a JSON object
// is skipped.
//
// LINESIM_FUZZ_SEED_DIR=DIR: runs scenarios/cross_line.yaml,
// fleet_line.yaml and worker_crossing.yaml for 0.2 s each with their
// replay and writes each page's data into DIR, then exits; tools/fuzz.sh
// makes the seed corpus with it.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fuzz/fuzz_support.h"
#include "replay/replay_data.h"
#include "replay/replay_recorder.h"
#include "session/session.h"

namespace {

using Json = nlohmann::json;
using linesim::replay::ReplayData;

void Fail(const std::string& why) {
  std::fprintf(stderr, "replay data fuzzer: %s\n", why.c_str());
  std::abort();
}

void WriteSeeds(const std::string& dir) {
  for (const char* name : {"cross_line", "fleet_line", "worker_crossing"}) {
    linesim::session::Session session(
        std::string(LINESIM_SOURCE_DIR) + "/scenarios/" + name + ".yaml", {"duration_s=0.2"});
    // The scenario's own figure bound, as a run folder's replay has it.
    const auto& bound = session.scenario().robot->figure_bound;
    linesim::replay::ReplayRecorder recorder(
        linesim::replay::ReplaySpecFor(session.scenario(), bound.value_m, bound.label));
    session.AddObserver(&recorder);
    session.Run();
    std::ofstream(dir + "/" + name + ".json", std::ios::binary) << recorder.DataJson();
  }
}

// The input's JSON read as the page reads it: what is missing or of
// another type stays at its default.
std::string Text(const Json& o, const char* key) {
  const auto it = o.find(key);
  return it != o.end() && it->is_string() ? it->get<std::string>() : "";
}

double Number(const Json& v) {
  return v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

double Number(const Json& o, const char* key) {
  const auto it = o.find(key);
  return it != o.end() ? Number(*it) : 0.0;
}

std::vector<double> Numbers(const Json& o, const char* key) {
  std::vector<double> out;
  const auto it = o.find(key);
  if (it == o.end() || !it->is_array()) return out;
  for (const auto& v : *it) out.push_back(Number(v));
  return out;
}

const Json& List(const Json& o, const char* key) {
  static const Json empty = Json::array();
  const auto it = o.find(key);
  return it != o.end() && it->is_array() ? *it : empty;
}

linesim::models::Solid SolidOf(const Json& o) {
  linesim::models::Solid s;
  s.kind = Text(o, "shape") == "cylinder" ? linesim::models::Solid::Kind::kCylinder
                                          : linesim::models::Solid::Kind::kBox;
  s.x_m = Number(o, "x");
  s.y_m = Number(o, "y");
  s.yaw_rad = Number(o, "yaw");
  s.length_m = Number(o, "length");
  s.width_m = Number(o, "width");
  s.radius_m = Number(o, "radius");
  return s;
}

void ReadScene(const Json& j, ReplayData& d) {
  linesim::models::Scene& scene = d.scene;
  for (const auto& s : List(j, "surfaces")) {
    scene.surfaces.push_back({});
    if (s.is_string()) scene.surfaces.back().name = s.get<std::string>();
  }
  if (j.contains("floor") && j["floor"].is_object()) {
    const Json& f = j["floor"];
    scene.floor.min_x_m = Number(f, "min_x");
    scene.floor.max_x_m = Number(f, "max_x");
    scene.floor.min_y_m = Number(f, "min_y");
    scene.floor.max_y_m = Number(f, "max_y");
  }
  for (const auto& b : List(j, "belts")) {
    if (!b.is_object()) continue;
    linesim::models::Belt belt;
    belt.name = Text(b, "name");
    belt.area = {Number(b, "x"), Number(b, "y"), Number(b, "length"), Number(b, "width"),
                 Number(b, "dir")};
    scene.belts.push_back(belt);
    d.belt_travel.push_back(Numbers(b, "travel"));
    d.belt_on.push_back(Numbers(b, "on"));
  }
  for (const auto& o : List(j, "obstacles")) {
    if (o.is_object()) scene.obstacles.push_back({Text(o, "name"), Text(o, "kind"), SolidOf(o)});
  }
  for (const auto& c : List(j, "carried")) {
    if (!c.is_object()) continue;
    linesim::models::CarriedObject carried;
    carried.name = Text(c, "name");
    const double belt = Number(c, "belt");
    carried.belt = std::abs(belt) < 1e6 ? static_cast<int>(belt) : -1;
    carried.solid = SolidOf(c);
    scene.carried.push_back(carried);
  }
  for (const auto& t : List(j, "terrain")) {
    if (!t.is_object()) continue;
    linesim::models::TerrainPiece p;
    p.name = Text(t, "name");
    p.center_x_m = Number(t, "x");
    p.center_y_m = Number(t, "y");
    p.yaw_rad = Number(t, "yaw");
    p.length_m = Number(t, "length");
    p.width_m = Number(t, "width");
    scene.terrain.push_back(p);
  }
}

void ReadRun(const Json& j, ReplayData& d) {
  d.t = Numbers(j, "t");
  d.x = Numbers(j, "x");
  d.y = Numbers(j, "y");
  d.yaw = Numbers(j, "yaw");
  for (const auto& p : List(j, "path")) {
    if (p.is_array() && p.size() == 2) d.path.push_back({Number(p[0]), Number(p[1])});
  }
  for (const auto& w : List(j, "wheels")) {
    if (!w.is_object()) continue;
    d.wheels.push_back({Numbers(w, "x"), Numbers(w, "y"), Numbers(w, "surface")});
  }
  for (const auto& p : List(j, "plots")) {
    if (!p.is_object()) continue;
    ReplayData::Plot plot{
        Text(p, "title"), Text(p, "unit"), Number(p, "bound"), Text(p, "bound_label"), {}};
    for (const auto& c : List(p, "curves")) {
      if (c.is_object()) plot.curves.push_back({Text(c, "label"), Numbers(c, "values")});
    }
    d.plots.push_back(std::move(plot));
  }
  for (const auto& m : List(j, "movers")) {
    if (!m.is_object()) continue;
    d.movers.push_back({Text(m, "name"), m.value("robot", false) == true, Number(m, "length"),
                        Number(m, "width"), Number(m, "radius"), Numbers(m, "x"), Numbers(m, "y"),
                        Numbers(m, "yaw")});
  }
  for (const auto& l : List(j, "lasers")) {
    if (!l.is_object()) continue;
    ReplayData::Laser laser{Text(l, "name"),
                            Number(l, "mount_x"),
                            Number(l, "mount_y"),
                            Number(l, "mount_yaw"),
                            Number(l, "first_beam"),
                            Number(l, "beam_step"),
                            -1.0,
                            {}};
    for (const auto& s : List(l, "scans")) {
      if (!s.is_object()) continue;
      ReplayData::Scan scan;
      scan.time_s = Number(s, "t");
      const auto pose = Numbers(s, "pose");
      if (pose.size() == 3) {
        scan.x = pose[0];
        scan.y = pose[1];
        scan.yaw = pose[2];
      }
      // The page's millimetres as the unit's metres.
      for (const double mm : Numbers(s, "ranges_mm")) scan.ranges.push_back(mm / 1000.0);
      laser.scans.push_back(std::move(scan));
    }
    d.lasers.push_back(std::move(laser));
  }
  if (j.contains("outcome") && j["outcome"].is_object()) {
    const Json& o = j["outcome"];
    d.outcome = {Text(o, "status"), Number(o, "end_s"), Number(o, "stop_s"), Text(o, "message")};
  }
}

// Raw bytes as the texts a scenario gives: one piece per line.
void PutRawTexts(const std::string& raw, ReplayData& d) {
  std::vector<std::string> pieces;
  for (std::size_t a = 0; a <= raw.size();) {
    const std::size_t b = std::min(raw.find('\n', a), raw.size());
    pieces.push_back(raw.substr(a, b - a));
    a = b + 1;
  }
  std::size_t k = 0;
  const auto next = [&] { return pieces[k++ % pieces.size()]; };
  d.title = next();
  d.description = next();
  for (auto& s : d.scene.surfaces) s.name = next();
  for (auto& b : d.scene.belts) b.name = next();
  for (auto& o : d.scene.obstacles) o.name = next();
  for (auto& p : d.plots) p.title = next();
  for (auto& m : d.movers) m.name = next();
  d.outcome.message = next();
}

bool IsUtf8(const std::string& s) {
  try {
    (void)Json(s).dump();  // nlohmann refuses ill-formed UTF-8 (type_error 316)
    return true;
  } catch (const Json::type_error&) {
    return false;
  }
}

// A text comes back byte for byte when it is UTF-8; otherwise valid (the
// parse succeeded) with its ASCII bytes in their order (each ill-formed
// part is one U+FFFD: json_text::AppendString).
void ExpectText(const Json& got, const std::string& given, const char* what) {
  if (!got.is_string()) Fail(std::string(what) + ": not a string");
  const std::string& s = got.get_ref<const std::string&>();
  if (IsUtf8(given)) {
    if (s != given) Fail(std::string(what) + ": changed");
    return;
  }
  std::string ascii_given, ascii_got;
  for (char c : given) {
    if (static_cast<unsigned char>(c) < 0x80) ascii_given += c;
  }
  for (char c : s) {
    if (static_cast<unsigned char>(c) < 0x80) ascii_got += c;
  }
  if (ascii_given != ascii_got) Fail(std::string(what) + ": its ASCII text changed");
}

void ExpectNumber(const Json& got, double given, int decimals, const char* what) {
  if (!std::isfinite(given)) {
    if (!got.is_null()) Fail(std::string(what) + ": not finite, but not null");
    return;
  }
  if (!got.is_number()) Fail(std::string(what) + ": not a number");
  const double value = got.get<double>();
  const double scale = std::pow(10.0, decimals);
  const double tolerance =
      std::abs(given * scale) < 9e15 ? 0.5 / scale * (1 + 1e-9) + std::abs(given) * 1e-15 : 0.0;
  if (!(std::abs(value - given) <= tolerance)) {
    Fail(std::string(what) + ": " + Json(given).dump() + " came back as " + got.dump());
  }
}

void ExpectNumbers(const Json& got, const std::vector<double>& given, int decimals,
                   const char* what) {
  if (!got.is_array() || got.size() != given.size()) Fail(std::string(what) + ": wrong length");
  for (std::size_t i = 0; i < given.size(); ++i) ExpectNumber(got[i], given[i], decimals, what);
}

void Check(const ReplayData& d) {
  const std::string json = linesim::replay::DataJson(d);
  if (json.find('<') != std::string::npos) Fail("a '<' in the data: it could end its element");
  if (linesim::replay::DataJson(d) != json) Fail("the same data gave other bytes");
  const Json back = Json::parse(json, nullptr, /*allow_exceptions=*/false);
  if (back.is_discarded()) Fail("the data is not valid JSON (or not UTF-8)");
  ExpectText(back["title"], d.title, "title");
  ExpectText(back["description"], d.description, "description");
  for (std::size_t i = 0; i < d.scene.surfaces.size(); ++i) {
    ExpectText(back["surfaces"][i], d.scene.surfaces[i].name, "surface name");
  }
  for (std::size_t i = 0; i < d.scene.belts.size(); ++i) {
    ExpectText(back["belts"][i]["name"], d.scene.belts[i].name, "belt name");
    ExpectNumbers(back["belts"][i]["travel"], d.belt_travel[i], 4, "belt travel");
  }
  ExpectNumbers(back["t"], d.t, 6, "t");
  ExpectNumbers(back["x"], d.x, 4, "x");
  ExpectNumbers(back["yaw"], d.yaw, 5, "yaw");
  for (std::size_t p = 0; p < d.plots.size(); ++p) {
    ExpectText(back["plots"][p]["title"], d.plots[p].title, "plot title");
    for (std::size_t c = 0; c < d.plots[p].curves.size(); ++c) {
      ExpectNumbers(back["plots"][p]["curves"][c]["values"], d.plots[p].curves[c].values, 5,
                    "curve");
    }
  }
  for (std::size_t m = 0; m < d.movers.size(); ++m) {
    ExpectText(back["movers"][m]["name"], d.movers[m].name, "mover name");
  }
  for (std::size_t k = 0; k < d.lasers.size(); ++k) {
    const ReplayData::Laser& l = d.lasers[k];
    for (std::size_t s = 0; s < l.scans.size(); ++s) {
      const Json& mm = back["lasers"][k]["scans"][s]["ranges_mm"];
      if (!mm.is_array() || mm.size() != l.scans[s].ranges.size()) Fail("ranges: wrong length");
      for (std::size_t b = 0; b < mm.size(); ++b) {
        const double r = l.scans[s].ranges[b];
        const bool echo = r != l.no_return_m && std::abs(r) < 1e12;
        if (!mm[b].is_number_integer()) Fail("a range is not whole millimetres");
        if (!echo && mm[b].get<std::int64_t>() != -1) Fail("no echo is not -1");
        if (echo && std::abs(mm[b].get<double>() - r * 1000.0) > 0.5 + std::abs(r) * 1e-12) {
          Fail("a range came back wrong");
        }
      }
    }
  }
  ExpectText(back["outcome"]["message"], d.outcome.message, "outcome message");
  // The page around it: its template, untouched.
  const std::string html = linesim::replay::PageHtml(d);
  if (html.size() != linesim::replay::PageBytesWithoutData() + json.size()) {
    Fail("the page is not its template with the data inside");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seed_dir = std::getenv("LINESIM_FUZZ_SEED_DIR")) {
    WriteSeeds(seed_dir);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = input.find('\0');
  const Json j = Json::parse(input.substr(0, nul), nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) return 0;
  ReplayData d;
  d.title = Text(j, "title");
  d.description = Text(j, "description");
  d.task = Text(j, "task");
  ReadScene(j, d);
  ReadRun(j, d);
  if (nul != std::string::npos) PutRawTexts(input.substr(nul + 1), d);
  Check(d);
  return 0;
}
