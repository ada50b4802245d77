#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "config/scenario_error.h"
#include "cosim/time.h"

namespace linesim::config {

/// "a.b" + "c" -> "a.b.c".
std::string JoinPath(const std::string& path, const std::string& key);

/// "; closest: path.a, path.b" with the candidates close to `name` as full
/// paths under `path`, or "" when none is close.
std::string ClosestPathsHint(const std::string& path, const std::string& name,
                             const std::vector<std::string>& candidates);

/// "a, b, c".
std::string JoinNames(const std::vector<std::string>& names);

/// Accepted interval of a number.
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;
};

/// Where a value of a generated tree came from: the node and the key path
/// of what the user wrote.
struct Origin {
  YAML::Node node;
  std::string path;
  /// The file `path` is in, when not the reader's own (a robot description
  /// a scenario names).
  std::string file;
};

/// Reads a YAML tree and collects issues with file, line and key path
/// instead of stopping at the first one.
class YamlReader {
 public:
  /// `overridden` holds the key paths set with --set, so that issues under
  /// them say so instead of pointing at a line.
  YamlReader(std::string file, std::set<std::string> overridden = {});

  void Error(const YAML::Node& at, const std::string& path, std::string message);
  /// An issue of another file than the reader's (a model file it read).
  void Error(const std::string& file, const YAML::Node& at, const std::string& path,
             std::string message);
  /// An issue with the key path itself (no such key), not with a value.
  void UnknownPath(const YAML::Node& at, const std::string& path, std::string message);
  void Add(const std::vector<Issue>& issues);
  /// From now on an issue of the reader's own file at a key path in
  /// `origins` (a generated tree's path) is reported at its origin instead.
  void SetOrigins(std::map<std::string, Origin> origins) { origins_ = std::move(origins); }
  bool ok() const { return issues_.empty(); }
  const std::vector<Issue>& issues() const { return issues_; }
  /// The file the reader's issues are of: its own, or the one an InFile
  /// guard names.
  const std::string& file() const { return file_; }

  /// While it exists, the reader reads another file (a model file read for
  /// the scenario): its issues name that file, never the command line.
  class InFile {
   public:
    InFile(YamlReader& r, std::string file) : r_(r), saved_(r.file_) { r_.file_ = std::move(file); }
    ~InFile() { r_.file_ = std::move(saved_); }
    InFile(const InFile&) = delete;
    InFile& operator=(const InFile&) = delete;

   private:
    YamlReader& r_;
    std::string saved_;
  };
  /// While it exists, the key paths of the reader's own file are read as
  /// `scope` maps them: the paths a concern reads at ("task.speed_mps") are
  /// reported where the user wrote them ("robots.1.task.speed_mps") when a
  /// part of the file is read as if it were a whole one.
  class PathScope {
   public:
    PathScope(YamlReader& r, std::function<std::string(const std::string&)> scope)
        : r_(r), saved_(std::move(r.scope_)) {
      r_.scope_ = std::move(scope);
    }
    ~PathScope() { r_.scope_ = std::move(saved_); }
    PathScope(const PathScope&) = delete;
    PathScope& operator=(const PathScope&) = delete;

   private:
    YamlReader& r_;
    std::function<std::string(const std::string&)> saved_;
  };
  /// `path` of the reader's own file as the current PathScope maps it.
  std::string Scoped(const std::string& path) const { return scope_ ? scope_(path) : path; }
  static int LineOf(const YAML::Node& node);
  /// A scalar that reads as a number other than NaN, without reporting.
  static std::optional<double> DecodeReal(const YAML::Node& node);

  bool ExpectMap(const YAML::Node& node, const std::string& path);
  bool ExpectSequence(const YAML::Node& node, const std::string& path);
  /// Reports every key of `map` not in `allowed`, with the closest allowed
  /// keys as full paths.
  void CheckKeys(const YAML::Node& map, const std::string& path,
                 const std::vector<std::string>& allowed);

  /// A key of `map`; when absent, `fallback` (or an issue if none is given).
  double Real(const YAML::Node& map, const std::string& path, const std::string& key,
              std::optional<double> fallback, Range range = {});
  /// A time in seconds (`fallback` and `range` too) as integer nanoseconds.
  /// Besides the range, refuses a nonzero time below 1 ns (it would round
  /// to 0 or 1 ns silently) and one too large for int64 nanoseconds.
  cosim::TimeNs Time(const YAML::Node& map, const std::string& path, const std::string& key,
                     std::optional<double> fallback, Range range = {});
  std::int64_t Integer(const YAML::Node& map, const std::string& path, const std::string& key,
                       std::optional<std::int64_t> fallback, std::int64_t min, std::int64_t max);
  bool Boolean(const YAML::Node& map, const std::string& path, const std::string& key,
               std::optional<bool> fallback);
  /// With a non-empty `allowed`, the value must be one of them.
  std::string String(const YAML::Node& map, const std::string& path, const std::string& key,
                     std::optional<std::string> fallback,
                     const std::vector<std::string>& allowed = {});

  /// Scalar readers for a node already looked up; each reports a bad value
  /// at `path` and returns nothing.
  std::optional<double> AsReal(const YAML::Node& node, const std::string& path, Range range = {});
  std::optional<std::int64_t> AsInteger(const YAML::Node& node, const std::string& path,
                                        std::int64_t min, std::int64_t max);
  std::optional<bool> AsBoolean(const YAML::Node& node, const std::string& path);
  std::optional<std::string> AsString(const YAML::Node& node, const std::string& path);
  /// A point [x, y] in metres, each coordinate in `range`.
  std::optional<std::array<double, 2>> AsPoint(const YAML::Node& node, const std::string& path,
                                               Range range = {});

  /// Whether `path`, or a key above it, was set with --set.
  bool FromCommandLine(const std::string& path) const;
  /// Makes FromCommandLine (and ConflictKey) answer as `other` does: a
  /// reader of a merged tree whose issues `other` reports again.
  void ShareCommandLine(const YamlReader& other) {
    overridden_ = other.overridden_;
    command_line_origins_ = other.origins_;
  }
  /// Of two keys under `path` whose values contradict each other (a min
  /// above its max), the one to report at: the one the command line set
  /// when only one of them was (the user changed that one), else `second`.
  std::string ConflictKey(const std::string& path, const std::string& first,
                          const std::string& second) const;
  /// The key paths given on the command line with no value (`--set key=`).
  /// The tree holds null there, which a reader would take as absent and
  /// silently replace by its default: the typed readers (Real, Time,
  /// Integer, Boolean, String) refuse it instead, naming what they expect;
  /// LoadScenario refuses the others no reader reported (a section).
  void SetGivenWithoutValue(std::set<std::string> paths) { without_value_ = std::move(paths); }

 private:
  /// `path` as the user wrote it: through the origin of it or of its
  /// longest ancestor that has one, in the reader's own file; else `path`.
  std::string UserPath(const std::string& path) const;
  const YAML::Node Lookup(const YAML::Node& map, const std::string& path, const std::string& key,
                          bool required);
  /// Reports and returns true when `key` of `map` holds no value because
  /// the command line gave none; `expected` says what the key takes.
  bool RefuseNoValue(const YAML::Node& map, const std::string& path, const std::string& key,
                     const std::string& expected, bool has_default);

  std::string file_;
  const std::string own_file_;
  std::set<std::string> overridden_;
  std::set<std::string> without_value_;
  std::map<std::string, Origin> origins_;
  std::function<std::string(const std::string&)> scope_;
  /// Origins seen only by FromCommandLine (ShareCommandLine).
  std::map<std::string, Origin> command_line_origins_;
  std::vector<Issue> issues_;
};

/// The value of `key` in `map`, or an undefined node (never an invalid one,
/// which yaml-cpp would throw on) when `map` is not a map or lacks the key.
YAML::Node Child(const YAML::Node& map, const std::string& key);

/// A short rendering of a node for messages: the scalar, or "a map"/"a list".
std::string Describe(const YAML::Node& node);

}  // namespace linesim::config
