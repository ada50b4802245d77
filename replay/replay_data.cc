#include "replay/replay_data.h"

#include <openssl/evp.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "json_text/json_string.h"

namespace linesim::replay {

namespace {

void AppendInt(std::string& out, std::int64_t v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

// Numbers in fixed notation with a set number of decimals, trailing zeros
// dropped: the value scaled by 10^decimals and rounded to an integer
// (llround: exact, the same on every CPU), written as digits; the same
// double gives the same text everywhere, whatever the locale. Not finite:
// null. Beyond 9e15 after scaling (nothing a replay draws): the shortest
// round-trip text (at most 24 characters, so kMaxNumberBytes holds).
void AppendFixed(std::string& out, double v, int decimals) {
  static constexpr double kScale[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9};
  static constexpr std::int64_t kPower[] = {1,      10,      100,      1000,      10000,
                                            100000, 1000000, 10000000, 100000000, 1000000000};
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  const double scaled = v * kScale[decimals];
  if (!(std::abs(scaled) < 9e15)) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
    return;
  }
  std::int64_t n = std::llround(scaled);
  if (n < 0) {
    out += '-';
    n = -n;
  }
  AppendInt(out, n / kPower[decimals]);
  std::int64_t fraction = n % kPower[decimals];
  if (fraction == 0) return;
  int digits = decimals;
  while (fraction % 10 == 0) {
    fraction /= 10;
    --digits;
  }
  out += '.';
  char buf[16];
  for (int i = digits - 1; i >= 0; --i) {
    buf[i] = static_cast<char>('0' + fraction % 10);
    fraction /= 10;
  }
  out.append(buf, static_cast<std::size_t>(digits));
}

// A JSON string inside the page's <script> element.
void AppendString(std::string& out, const std::string& s) {
  json_text::AppendString(out, s, /*inside_html_script=*/true);
}

void AppendArray(std::string& out, const std::vector<double>& values, int decimals) {
  out += '[';
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += ',';
    AppendFixed(out, values[i], decimals);
  }
  out += ']';
}

// Decimals per quantity: 0.1 mm for positions and travels, 1e-5 rad
// (10 um at a metre) for angles, 1e-5 of the plotted signals' units (m,
// m/s, A), whole seconds to the nanosecond's 1e-6 for times (every sample
// time is a whole number of base steps, at least a microsecond).
constexpr int kMetres = 4;
constexpr int kRadians = 5;
constexpr int kSignal = 5;
constexpr int kSeconds = 6;

// A key and its value: `"key":` then the caller appends the value.
void Key(std::string& out, const char* key) {
  out += '"';
  out += key;
  out += "\":";
}

void Member(std::string& out, const char* key, double v, int decimals) {
  Key(out, key);
  AppendFixed(out, v, decimals);
  out += ',';
}

void StringMember(std::string& out, const char* key, const std::string& v) {
  Key(out, key);
  AppendString(out, v);
  out += ',';
}

void ArrayMember(std::string& out, const char* key, const std::vector<double>& v, int decimals) {
  Key(out, key);
  AppendArray(out, v, decimals);
  out += ',';
}

// Ends an object or list: its last member's comma becomes `close`.
void Close(std::string& out, char close) {
  if (out.back() == ',') {
    out.back() = close;
  } else {
    out += close;
  }
}

void AppendSolid(std::string& out, const models::Solid& s) {
  Key(out, "shape");
  out += s.kind == models::Solid::Kind::kBox ? "\"box\"," : "\"cylinder\",";
  Member(out, "x", s.x_m, kMetres);
  Member(out, "y", s.y_m, kMetres);
  Member(out, "yaw", s.yaw_rad, kRadians);
  Member(out, "length", s.length_m, kMetres);
  Member(out, "width", s.width_m, kMetres);
  Member(out, "radius", s.radius_m, kMetres);
}

void AppendScene(std::string& out, const models::Scene& scene, const ReplayData& d) {
  Key(out, "surfaces");
  out += '[';
  for (const models::Surface& s : scene.surfaces) {
    AppendString(out, s.name);
    out += ',';
  }
  Close(out, ']');
  out += ',';
  Key(out, "floor");
  out += '{';
  Member(out, "min_x", scene.floor.min_x_m, kMetres);
  Member(out, "max_x", scene.floor.max_x_m, kMetres);
  Member(out, "min_y", scene.floor.min_y_m, kMetres);
  Member(out, "max_y", scene.floor.max_y_m, kMetres);
  Key(out, "surface");
  AppendInt(out, scene.floor.surface);
  out += "},";
  Key(out, "belts");
  out += '[';
  for (std::size_t b = 0; b < scene.belts.size(); ++b) {
    const models::Belt& belt = scene.belts[b];
    out += '{';
    StringMember(out, "name", belt.name);
    Member(out, "x", belt.area.center_x_m, kMetres);
    Member(out, "y", belt.area.center_y_m, kMetres);
    Member(out, "length", belt.area.length_m, kMetres);
    Member(out, "width", belt.area.width_m, kMetres);
    Member(out, "dir", belt.area.direction_rad, kRadians);
    Key(out, "surface");
    AppendInt(out, belt.surface);
    out += ',';
    ArrayMember(out, "travel", b < d.belt_travel.size() ? d.belt_travel[b] : std::vector<double>{},
                kMetres);
    ArrayMember(out, "on", b < d.belt_on.size() ? d.belt_on[b] : std::vector<double>{}, 0);
    Close(out, '}');
    out += ',';
  }
  Close(out, ']');
  out += ',';
  Key(out, "obstacles");
  out += '[';
  for (const models::Obstacle& o : scene.obstacles) {
    out += '{';
    StringMember(out, "name", o.name);
    StringMember(out, "kind", o.kind);
    AppendSolid(out, o.solid);
    Close(out, '}');
    out += ',';
  }
  Close(out, ']');
  out += ',';
  Key(out, "carried");
  out += '[';
  for (const models::CarriedObject& c : scene.carried) {
    out += '{';
    StringMember(out, "name", c.name);
    Key(out, "belt");
    AppendInt(out, c.belt);
    out += ',';
    // The travel over which it lies on its belt (outside: lifted off).
    const bool has_belt = c.belt >= 0 && static_cast<std::size_t>(c.belt) < scene.belts.size();
    const auto range = has_belt ? models::CarriedTravelRange(
                                      scene.belts[static_cast<std::size_t>(c.belt)].area, c.solid)
                                : std::array<double, 2>{0.0, 0.0};
    Member(out, "travel_min", range[0], kMetres);
    Member(out, "travel_max", range[1], kMetres);
    AppendSolid(out, c.solid);
    Close(out, '}');
    out += ',';
  }
  Close(out, ']');
  out += ',';
  Key(out, "terrain");
  out += '[';
  for (const models::TerrainPiece& p : scene.terrain) {
    out += '{';
    StringMember(out, "name", p.name);
    Member(out, "x", p.center_x_m, kMetres);
    Member(out, "y", p.center_y_m, kMetres);
    Member(out, "yaw", p.yaw_rad, kRadians);
    // The footprint of its top face seen from above.
    Member(out, "length", p.length_m * std::cos(p.pitch_rad), kMetres);
    Member(out, "width", p.width_m * std::cos(p.roll_rad), kMetres);
    Key(out, "surface");
    AppendInt(out, p.surface);
    out += "},";
  }
  Close(out, ']');
  out += ',';
}

void AppendPlots(std::string& out, const ReplayData& d) {
  Key(out, "plots");
  out += '[';
  for (const ReplayData::Plot& plot : d.plots) {
    out += '{';
    StringMember(out, "title", plot.title);
    StringMember(out, "unit", plot.unit);
    Member(out, "bound", plot.bound, kSignal);
    StringMember(out, "bound_label", plot.bound_label);
    Key(out, "curves");
    out += '[';
    for (const ReplayData::Curve& c : plot.curves) {
      out += '{';
      StringMember(out, "label", c.label);
      ArrayMember(out, "values", c.values, kSignal);
      Close(out, '}');
      out += ',';
    }
    Close(out, ']');
    out += "},";
  }
  Close(out, ']');
  out += ',';
}

void AppendMovers(std::string& out, const ReplayData& d) {
  Key(out, "movers");
  out += '[';
  for (const ReplayData::Mover& m : d.movers) {
    out += '{';
    StringMember(out, "name", m.name);
    Key(out, "robot");
    out += m.robot ? "true," : "false,";
    Member(out, "length", m.length_m, kMetres);
    Member(out, "width", m.width_m, kMetres);
    Member(out, "radius", m.radius_m, kMetres);
    ArrayMember(out, "x", m.x, kMetres);
    ArrayMember(out, "y", m.y, kMetres);
    ArrayMember(out, "yaw", m.yaw, kRadians);
    Close(out, '}');
    out += ',';
  }
  Close(out, ']');
  out += ',';
}

// Ranges in whole millimetres (the S300 and LMS151 report in mm), -1 for
// no echo.
void AppendLasers(std::string& out, const ReplayData& d) {
  Key(out, "lasers");
  out += '[';
  for (const ReplayData::Laser& l : d.lasers) {
    out += '{';
    StringMember(out, "name", l.name);
    Member(out, "mount_x", l.mount_x_m, kMetres);
    Member(out, "mount_y", l.mount_y_m, kMetres);
    Member(out, "mount_yaw", l.mount_yaw_rad, kRadians);
    Member(out, "first_beam", l.first_beam_rad, 7);
    Member(out, "beam_step", l.beam_step_rad, 9);
    Key(out, "scans");
    out += '[';
    for (const ReplayData::Scan& scan : l.scans) {
      out += '{';
      Member(out, "t", scan.time_s, kSeconds);
      Key(out, "pose");
      out += '[';
      AppendFixed(out, scan.x, kMetres);
      out += ',';
      AppendFixed(out, scan.y, kMetres);
      out += ',';
      AppendFixed(out, scan.yaw, kRadians);
      out += "],";
      Key(out, "ranges_mm");
      out += '[';
      for (const double range : scan.ranges) {
        // A range beyond any scanner's (1e12 m) is drawn as no echo too:
        // its millimetres would not fit the integer.
        if (range == l.no_return_m || !(std::abs(range) < 1e12)) {
          out += "-1";
        } else {
          AppendInt(out, std::llround(range * 1000.0));
        }
        out += ',';
      }
      Close(out, ']');
      out += "},";
    }
    Close(out, ']');
    out += "},";
  }
  Close(out, ']');
}

// The standard base64 alphabet of a SHA-256 digest, as a policy's hash
// source names it (CSP Level 3, "hash-source").
std::string Sha256Base64(std::string_view text) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(text.data(), text.size(), digest, &length, EVP_sha256(), nullptr) != 1) {
    throw std::runtime_error("replay page: SHA-256 failed");
  }
  unsigned char encoded[4 * ((EVP_MAX_MD_SIZE + 2) / 3) + 1];
  const int n = EVP_EncodeBlock(encoded, digest, static_cast<int>(length));
  return std::string(reinterpret_cast<const char*>(encoded), static_cast<std::size_t>(n));
}

// The text of the element that starts with `open` (up to `close`).
std::string_view ElementText(std::string_view page, std::string_view open, std::string_view close) {
  const std::size_t a = page.find(open);
  const std::size_t b = a == std::string_view::npos ? a : page.find(close, a + open.size());
  if (b == std::string_view::npos) {
    throw std::logic_error("replay page template without its " + std::string(open) + " element");
  }
  return page.substr(a + open.size(), b - a - open.size());
}

// The template with its policy: only its own script and style (by their
// SHA-256) may run; nothing may be loaded, connected to, framed or
// submitted; no inline handler, no style attribute. The data element is
// JSON (type application/json): a data block, never run.
struct Template {
  std::string head;  // up to the data
  std::string tail;  // after the data
};

const Template& PageParts() {
  static const Template parts = [] {
    std::string page = PageTemplate();
    const std::string policy = "default-src 'none'; script-src 'sha256-" +
                               Sha256Base64(ElementText(page, "<script>", "</script>")) +
                               "'; style-src 'sha256-" +
                               Sha256Base64(ElementText(page, "<style>", "</style>")) +
                               "'; base-uri 'none'; form-action 'none'";
    const std::size_t p = page.find(kPolicyMarker);
    if (p == std::string::npos) throw std::logic_error("replay page template without its policy");
    page.replace(p, std::strlen(kPolicyMarker), policy);
    const std::size_t at = page.find(kDataMarker);
    if (at == std::string::npos) {
      throw std::logic_error("replay page template without its data marker");
    }
    return Template{page.substr(0, at), page.substr(at + std::strlen(kDataMarker))};
  }();
  return parts;
}

}  // namespace

std::string DataJson(const ReplayData& d) {
  std::string out;
  out.reserve(std::size_t{2} << 20);  // a 20 s cross_line: 1.5 MB
  out += '{';
  Key(out, "format");
  out += "1,";
  StringMember(out, "title", d.title);
  StringMember(out, "description", d.description);
  StringMember(out, "task", d.task);
  Key(out, "rates");
  out += '{';
  Member(out, "frame_hz", d.frame_hz, kSignal);
  Member(out, "scan_hz", d.scan_hz, kSignal);
  Close(out, '}');
  out += ',';
  Key(out, "outcome");
  out += '{';
  StringMember(out, "status", d.outcome.status);
  Member(out, "end_s", d.outcome.end_s, kSeconds);
  Member(out, "stop_s", d.outcome.stop_s, kSeconds);
  StringMember(out, "message", d.outcome.message);
  Close(out, '}');
  out += ',';
  AppendScene(out, d.scene, d);
  Key(out, "path");
  out += '[';
  for (const auto& p : d.path) {
    out += '[';
    AppendFixed(out, p[0], kMetres);
    out += ',';
    AppendFixed(out, p[1], kMetres);
    out += "],";
  }
  Close(out, ']');
  out += ',';
  Key(out, "body");
  out += '{';
  Member(out, "length", d.body_length_m, kMetres);
  Member(out, "width", d.body_width_m, kMetres);
  Close(out, '}');
  out += ',';
  ArrayMember(out, "t", d.t, kSeconds);
  ArrayMember(out, "x", d.x, kMetres);
  ArrayMember(out, "y", d.y, kMetres);
  ArrayMember(out, "yaw", d.yaw, kRadians);
  Key(out, "wheels");
  out += '[';
  for (const ReplayData::Wheel& w : d.wheels) {
    out += '{';
    ArrayMember(out, "x", w.x, kMetres);
    ArrayMember(out, "y", w.y, kMetres);
    ArrayMember(out, "surface", w.surface, 0);
    Close(out, '}');
    out += ',';
  }
  Close(out, ']');
  out += ',';
  AppendPlots(out, d);
  AppendMovers(out, d);
  AppendLasers(out, d);
  out += '}';
  return out;
}

std::string PageHtml(const ReplayData& data) {
  const Template& parts = PageParts();
  return parts.head + DataJson(data) + parts.tail;
}

std::uint64_t PageBytesWithoutData() {
  const Template& parts = PageParts();
  return parts.head.size() + parts.tail.size();
}

}  // namespace linesim::replay
