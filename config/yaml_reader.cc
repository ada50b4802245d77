#include "config/yaml_reader.h"

#include <cmath>
#include <cstdint>

#include "cosim/closest_names.h"

namespace linesim::config {

std::string JoinPath(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string ClosestPathsHint(const std::string& path, const std::string& name,
                             const std::vector<std::string>& candidates) {
  std::vector<std::string> paths;
  for (const auto& c : cosim::ClosestNames(name, candidates)) paths.push_back(JoinPath(path, c));
  return paths.empty() ? "" : "; closest: " + JoinNames(paths);
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

YAML::Node Child(const YAML::Node& map, const std::string& key) {
  if (map.IsDefined() && map.IsMap()) {
    for (const auto& kv : map) {
      if (kv.first.Scalar() == key) return kv.second;
    }
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

std::string Describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsMap()) return "a map";
  if (node.IsSequence()) return "a list";
  // Long values (a whole file read as one scalar) are cut for messages.
  const std::string& v = node.Scalar();
  return "'" + (v.size() > 60 ? v.substr(0, 57) + "..." : v) + "'";
}

YamlReader::YamlReader(std::string file, std::set<std::string> overridden)
    : file_(file), own_file_(std::move(file)), overridden_(std::move(overridden)) {}

int YamlReader::LineOf(const YAML::Node& node) {
  if (!node.IsDefined() || node.Mark().is_null()) return 0;
  return node.Mark().line + 1;
}

std::string YamlReader::ConflictKey(const std::string& path, const std::string& first,
                                    const std::string& second) const {
  const bool first_set = FromCommandLine(JoinPath(path, first));
  const bool second_set = FromCommandLine(JoinPath(path, second));
  return first_set && !second_set ? first : second;
}

bool YamlReader::FromCommandLine(const std::string& path) const {
  // The path as given, and as the user wrote it (a generated tree's path
  // has its origin: scene.belts.0.x of line.belts.0.x).
  const std::string user = UserPath(path);
  for (const auto& o : overridden_) {
    for (const std::string* p : {&path, &user}) {
      if (*p == o || p->rfind(o + ".", 0) == 0) return true;
    }
  }
  return false;
}

std::string YamlReader::UserPath(const std::string& path) const {
  std::string rest;
  for (std::string prefix = path;;) {
    for (const auto* origins : {&origins_, &command_line_origins_}) {
      if (const auto it = origins->find(prefix); it != origins->end()) {
        return it->second.file.empty() ? it->second.path + rest : path;
      }
    }
    const auto dot = prefix.rfind('.');
    if (dot == std::string::npos) return path;
    rest = path.substr(dot);
    prefix.resize(dot);
  }
}

void YamlReader::Error(const YAML::Node& at, const std::string& path, std::string message) {
  Error(file_, at, path, std::move(message));
}

void YamlReader::Add(const std::vector<Issue>& issues) {
  issues_.insert(issues_.end(), issues.begin(), issues.end());
}

void YamlReader::Error(const std::string& file, const YAML::Node& at,
                       const std::string& read_path, std::string message) {
  const std::string path = file == own_file_ ? Scoped(read_path) : read_path;
  // The origin of the path, or of the longest of its ancestors that has one
  // (a value below a derived map keeps its place under the user's key).
  auto origin = origins_.end();
  std::string rest;
  if (file == own_file_) {
    for (std::string prefix = path;;) {
      origin = origins_.find(prefix);
      if (origin != origins_.end()) break;
      const auto dot = prefix.rfind('.');
      if (dot == std::string::npos) break;
      rest = path.substr(dot);
      prefix.resize(dot);
    }
  }
  const bool translated = origin != origins_.end();
  const bool exact = translated && rest.empty();
  Issue issue;
  issue.file = translated && !origin->second.file.empty() ? origin->second.file : file;
  issue.key_path = translated ? origin->second.path + rest : path;
  issue.message = std::move(message);
  issue.from_command_line = issue.file == own_file_ && FromCommandLine(issue.key_path);
  issue.line = issue.from_command_line ? 0 : LineOf(exact ? origin->second.node : at);
  // Below a derived key, a node the expansion made has no line: the user's
  // key it derives from has.
  if (translated && issue.line == 0 && !issue.from_command_line) {
    issue.line = LineOf(origin->second.node);
  }
  // A part of the file read more than once (a fleet's shared line, read
  // with every robot) reports a problem once.
  for (const Issue& i : issues_) {
    if (i.file == issue.file && i.line == issue.line && i.key_path == issue.key_path &&
        i.message == issue.message) {
      return;
    }
  }
  issues_.push_back(std::move(issue));
}

void YamlReader::UnknownPath(const YAML::Node& at, const std::string& path, std::string message) {
  const std::size_t before = issues_.size();
  Error(at, path, std::move(message));
  if (issues_.size() > before) issues_.back().unknown_path = true;
}

bool YamlReader::ExpectMap(const YAML::Node& node, const std::string& path) {
  if (node.IsMap()) return true;
  Error(node, path, "expected a map of keys, got " + Describe(node));
  return false;
}

bool YamlReader::ExpectSequence(const YAML::Node& node, const std::string& path) {
  if (node.IsSequence()) return true;
  Error(node, path, "expected a list, got " + Describe(node));
  return false;
}

void YamlReader::CheckKeys(const YAML::Node& map, const std::string& path,
                           const std::vector<std::string>& allowed) {
  if (!map.IsMap()) return;
  for (const auto& kv : map) {
    const std::string key = kv.first.Scalar();
    bool known = false;
    for (const auto& a : allowed) known |= (a == key);
    if (known) continue;
    UnknownPath(kv.first, JoinPath(path, key),
                "unknown key" + ClosestPathsHint(Scoped(path), key, allowed) +
                    "; expected one of: " + JoinNames(allowed));
  }
}

const YAML::Node YamlReader::Lookup(const YAML::Node& map, const std::string& path,
                                    const std::string& key, bool required) {
  const YAML::Node node = Child(map, key);
  if ((!node.IsDefined() || node.IsNull()) && required) {
    Error(map, JoinPath(path, key), "missing required key");
  }
  return node;
}

bool YamlReader::RefuseNoValue(const YAML::Node& map, const std::string& path,
                               const std::string& key, const std::string& expected,
                               bool has_default) {
  const std::string p = JoinPath(path, key);
  const YAML::Node node = Child(map, key);
  if ((node.IsDefined() && !node.IsNull()) || !without_value_.count(Scoped(p))) return false;
  Error(map, p,
        "no value given (--set " + Scoped(p) + "=): expected " + expected +
            (has_default ? "; to keep the default, leave the --set out" : ""));
  return true;
}

namespace {

// " >= 0 and <= 2" for a range, "" for every number.
std::string RangeText(const Range& range) {
  std::string want;
  if (std::isfinite(range.min)) {
    want = (range.min_exclusive ? "> " : ">= ") + YAML::Node(range.min).Scalar();
  }
  if (std::isfinite(range.max)) {
    want += (want.empty() ? "<= " : " and <= ") + YAML::Node(range.max).Scalar();
  }
  return want.empty() ? "" : " " + want;
}

}  // namespace

std::optional<double> YamlReader::DecodeReal(const YAML::Node& node) {
  double v = 0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, v) || std::isnan(v)) {
    return std::nullopt;
  }
  return v;
}

std::optional<double> YamlReader::AsReal(const YAML::Node& node, const std::string& path,
                                         Range range) {
  const std::optional<double> decoded = DecodeReal(node);
  if (!decoded) {
    Error(node, path, "expected a number, got " + Describe(node));
    return std::nullopt;
  }
  const double v = *decoded;
  const bool below = range.min_exclusive ? v <= range.min : v < range.min;
  if (below || v > range.max) {
    Error(node, path,
          "value " + node.Scalar() + " is out of range: expected a number" + RangeText(range));
    return std::nullopt;
  }
  return v;
}

namespace {

// Whether `s` is valid UTF-8 (RFC 3629: no overlong forms, no surrogates,
// nothing above U+10FFFF): the outputs (summary.json) can carry only that.
bool ValidUtf8(const std::string& s) {
  std::size_t i = 0;
  const std::size_t n = s.size();
  while (i < n) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t len = 0;
    std::uint32_t cp = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      len = 2;
      cp = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      len = 3;
      cp = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      len = 4;
      cp = c & 0x07;
    } else {
      return false;
    }
    if (i + len > n) return false;
    for (std::size_t k = 1; k < len; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (cc & 0x3F);
    }
    const std::uint32_t min = len == 2 ? 0x80 : len == 3 ? 0x800 : 0x10000;
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += len;
  }
  return true;
}

}  // namespace

std::optional<std::string> YamlReader::AsString(const YAML::Node& node, const std::string& path) {
  if (!node.IsScalar()) {
    Error(node, path, "expected a text value, got " + Describe(node));
    return std::nullopt;
  }
  if (!ValidUtf8(node.Scalar())) {
    Error(node, path, "is not valid UTF-8 text (the outputs can only carry UTF-8)");
    return std::nullopt;
  }
  return node.Scalar();
}

std::optional<std::array<double, 2>> YamlReader::AsPoint(const YAML::Node& node,
                                                         const std::string& path, Range range) {
  if (!node.IsSequence() || node.size() != 2) {
    Error(node, path, "expected a point [x, y] (m), got " + Describe(node));
    return std::nullopt;
  }
  const auto x = AsReal(node[0], JoinPath(path, "0"), range);
  const auto y = AsReal(node[1], JoinPath(path, "1"), range);
  if (!x || !y) return std::nullopt;
  return std::array<double, 2>{*x, *y};
}

double YamlReader::Real(const YAML::Node& map, const std::string& path, const std::string& key,
                        std::optional<double> fallback, Range range) {
  if (RefuseNoValue(map, path, key, "a number" + RangeText(range), fallback.has_value())) {
    return fallback.value_or(0.0);
  }
  const YAML::Node node = Lookup(map, path, key, !fallback.has_value());
  if (!node.IsDefined() || node.IsNull()) return fallback.value_or(0.0);
  return AsReal(node, JoinPath(path, key), range).value_or(fallback.value_or(0.0));
}

cosim::TimeNs YamlReader::Time(const YAML::Node& map, const std::string& path,
                               const std::string& key, std::optional<double> fallback,
                               Range range) {
  // Fallbacks are the caller's own values, in range by construction.
  const cosim::TimeNs otherwise = fallback ? cosim::SecondsToNs(*fallback) : 0;
  if (RefuseNoValue(map, path, key, "a time in seconds" + RangeText(range),
                    fallback.has_value())) {
    return otherwise;
  }
  const YAML::Node node = Lookup(map, path, key, !fallback.has_value());
  if (!node.IsDefined() || node.IsNull()) return otherwise;
  const std::string p = JoinPath(path, key);
  const auto seconds = AsReal(node, p, range);
  if (!seconds) return otherwise;
  // The one limit every time in seconds is checked against (cosim/time.h).
  if (std::abs(*seconds) > cosim::kMaxTimeSeconds) {
    Error(node, p,
          "value " + node.Scalar() + " is out of range: a time must be within +-4.6e9 s, the " +
              "longest time linesim represents (int64 nanoseconds, with room for a time plus a " +
              "duration)");
    return otherwise;
  }
  if (*seconds != 0.0 && std::abs(*seconds) < 1e-9) {
    Error(node, p,
          "value " + node.Scalar() + " is below one nanosecond, the time resolution: expected " +
              (range.min_exclusive && range.min == 0.0 ? "" : "0 or ") + "at least 1e-9 s");
    return otherwise;
  }
  return cosim::SecondsToNs(*seconds);
}

std::optional<std::int64_t> YamlReader::AsInteger(const YAML::Node& node, const std::string& path,
                                                  std::int64_t min, std::int64_t max) {
  std::int64_t v = 0;
  if (!node.IsScalar() || !YAML::convert<std::int64_t>::decode(node, v)) {
    Error(node, path, "expected an integer, got " + Describe(node));
    return std::nullopt;
  }
  if (v < min || v > max) {
    Error(node, path,
          "value " + std::to_string(v) + " is out of range: expected an integer from " +
              std::to_string(min) + " to " + std::to_string(max));
    return std::nullopt;
  }
  return v;
}

std::optional<bool> YamlReader::AsBoolean(const YAML::Node& node, const std::string& path) {
  bool v = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, v)) {
    Error(node, path, "expected true or false, got " + Describe(node));
    return std::nullopt;
  }
  return v;
}

std::int64_t YamlReader::Integer(const YAML::Node& map, const std::string& path,
                                 const std::string& key, std::optional<std::int64_t> fallback,
                                 std::int64_t min, std::int64_t max) {
  if (RefuseNoValue(map, path, key,
                    "an integer from " + std::to_string(min) + " to " + std::to_string(max),
                    fallback.has_value())) {
    return fallback.value_or(0);
  }
  const YAML::Node node = Lookup(map, path, key, !fallback.has_value());
  if (!node.IsDefined() || node.IsNull()) return fallback.value_or(0);
  return AsInteger(node, JoinPath(path, key), min, max).value_or(fallback.value_or(0));
}

bool YamlReader::Boolean(const YAML::Node& map, const std::string& path, const std::string& key,
                         std::optional<bool> fallback) {
  if (RefuseNoValue(map, path, key, "true or false", fallback.has_value())) {
    return fallback.value_or(false);
  }
  const YAML::Node node = Lookup(map, path, key, !fallback.has_value());
  if (!node.IsDefined() || node.IsNull()) return fallback.value_or(false);
  return AsBoolean(node, JoinPath(path, key)).value_or(fallback.value_or(false));
}

std::string YamlReader::String(const YAML::Node& map, const std::string& path,
                               const std::string& key, std::optional<std::string> fallback,
                               const std::vector<std::string>& allowed) {
  if (RefuseNoValue(map, path, key, allowed.empty() ? "a text" : "one of " + JoinNames(allowed),
                    fallback.has_value())) {
    return fallback.value_or("");
  }
  const YAML::Node node = Lookup(map, path, key, !fallback.has_value());
  if (!node.IsDefined() || node.IsNull()) return fallback.value_or("");
  const std::string p = JoinPath(path, key);
  const auto s = AsString(node, p);
  if (!s) return fallback.value_or("");
  // A required text left empty would make its item silently disappear (a
  // unit without a type, a connection or a metric without an end).
  if (!fallback && s->empty()) {
    Error(node, p, "is empty: expected a non-empty text");
    return "";
  }
  if (!allowed.empty()) {
    bool found = false;
    for (const auto& a : allowed) found |= (a == *s);
    if (!found) {
      Error(node, p,
            "'" + *s + "' is not allowed: expected one of " + JoinNames(allowed) +
                cosim::ClosestHint(*s, allowed));
      return fallback.value_or(allowed.front());
    }
  }
  return *s;
}

}  // namespace linesim::config
