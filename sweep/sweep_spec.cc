#include "sweep/sweep_spec.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <string_view>
#include <unordered_set>

#include "config/input_files.h"
#include "config/yaml_reader.h"
#include "cosim/system.h"
#include "cosim/variable_table.h"
#include "loader/scenario.h"
#include "loader/yaml_files.h"
#include "sweep/results_file.h"

namespace linesim::sweep {

namespace fs = std::filesystem;
using config::Child;
using config::Describe;
using config::Issue;
using config::JoinPath;
using config::ScenarioError;
using config::YamlReader;

namespace {

// A value of the sweep file as the text `--set` would take: scalars as
// written, lists and maps in YAML flow style.
std::string YamlText(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

// A dotted path as --set takes it: non-empty keys between the dots.
bool IsDottedPath(const std::string& path) {
  if (path.empty() || path.front() == '.' || path.back() == '.') return false;
  return path.find("..") == std::string::npos && path.find('=') == std::string::npos;
}

// The first repeated text of `items` (the index of its second place), if
// any; a hash set, so a range of a million values is checked in linear time
// (comparing each with all before it took minutes).
std::optional<std::size_t> FirstRepeat(const std::vector<std::string>& items) {
  std::unordered_set<std::string_view> seen;
  seen.reserve(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (!seen.insert(items[i]).second) return i;
  }
  return std::nullopt;
}

// Finite numbers only: an infinite bound would make NaN or inf values.
const config::Range kFinite{std::numeric_limits<double>::lowest(),
                            std::numeric_limits<double>::max()};

void ReadRange(const YAML::Node& range, const std::string& path, YamlReader& r, ParameterSpec& p) {
  if (!r.ExpectMap(range, path)) return;
  r.CheckKeys(range, path, {"from", "to", "count"});
  const std::size_t issues_before = r.issues().size();
  const double from = r.Real(range, path, "from", std::nullopt, kFinite);
  const double to = r.Real(range, path, "to", std::nullopt, kFinite);
  const std::int64_t count = r.Integer(range, path, "count", std::nullopt, 1, 1000000);
  if (r.issues().size() != issues_before) return;
  if (count > 1 && from == to) {
    r.Error(Child(range, "to"), JoinPath(path, "to"),
            "a range of " + std::to_string(count) + " values needs to != from");
    return;
  }
  if (count == 1 && from != to) {
    r.Error(Child(range, "count"), JoinPath(path, "count"),
            "a range from " + cosim::FormatValue(from) + " to " + cosim::FormatValue(to) +
                " needs a count of at least 2 (both ends are included)");
    return;
  }
  for (std::int64_t i = 0; i < count; ++i) {
    // Weighted ends, not from + (to - from) * f, whose difference can
    // overflow; the last value is `to` itself.
    const double f = static_cast<double>(i) / static_cast<double>(count - 1);
    const double v = i + 1 == count ? to : from * (1.0 - f) + to * f;
    // 12 significant digits: 0.05 + 2 * 0.05 is the 0.15 the user means,
    // not 0.15000000000000002, in the rows and the plots alike.
    char text[32];
    std::snprintf(text, sizeof text, "%.12g", v);
    p.values.push_back(cosim::FormatValue(std::strtod(text, nullptr)));
  }
}

void ReadRandom(const YAML::Node& random, const std::string& path, YamlReader& r,
                ParameterSpec& p) {
  if (!r.ExpectMap(random, path)) return;
  const std::string d =
      r.String(random, path, "distribution", std::nullopt, {"uniform", "normal", "log_uniform"});
  if (d == "normal") {
    r.CheckKeys(random, path, {"distribution", "mean", "std"});
    p.distribution = Distribution::kNormal;
    p.a = r.Real(random, path, "mean", std::nullopt, kFinite);
    p.b = r.Real(random, path, "std", std::nullopt, {0, kFinite.max});
  } else if (d == "uniform" || d == "log_uniform") {
    r.CheckKeys(random, path, {"distribution", "min", "max"});
    p.distribution = d == "uniform" ? Distribution::kUniform : Distribution::kLogUniform;
    const config::Range range = d == "uniform" ? kFinite : config::Range{0, kFinite.max, true};
    p.a = r.Real(random, path, "min", std::nullopt, range);
    p.b = r.Real(random, path, "max", std::nullopt, range);
    if (r.ok() && !(p.b >= p.a)) {
      r.Error(Child(random, "max"), JoinPath(path, "max"),
              "expected max >= min (" + cosim::FormatValue(p.a) + ")");
    }
  }
}

void ReadParameter(const YAML::Node& node, const std::string& path, YamlReader& r,
                   SweepSpec& spec) {
  if (!r.ExpectMap(node, path)) return;
  r.CheckKeys(node, path, {"path", "values", "range", "random"});
  ParameterSpec p;
  p.path = r.String(node, path, "path", std::nullopt);
  if (Child(node, "path").IsScalar() && !IsDottedPath(p.path)) {
    r.Error(Child(node, "path"), JoinPath(path, "path"),
            "expected a dotted path of keys, e.g. line.belts.0.speed_mps");
  } else if (p.path == "seed") {
    r.Error(Child(node, "path"), JoinPath(path, "path"),
            "each run's seed comes from the sweep (repeats:, seeds: and seed:), which results.csv "
            "reports in its seed column; for N seeds per point set repeats: N");
  }
  const char* kinds[] = {"values", "range", "random"};
  int given = 0;
  for (const char* k : kinds) given += Child(node, k).IsDefined() ? 1 : 0;
  if (given != 1) {
    r.Error(node, path,
            "expected exactly one of values: [...], range: {from, to, count} or "
            "random: {distribution, ...}");
    return;
  }
  if (const YAML::Node values = Child(node, "values"); values.IsDefined()) {
    const std::string vpath = JoinPath(path, "values");
    if (!r.ExpectSequence(values, vpath)) return;
    if (values.size() == 0) r.Error(values, vpath, "expected at least one value");
    for (std::size_t i = 0; i < values.size(); ++i) {
      p.values.push_back(YamlText(values[i]));
      // A row of results.csv is one line.
      if (p.values.back().find_first_of("\r\n") != std::string::npos) {
        r.Error(values[i], vpath + "." + std::to_string(i), "a value may not contain a line break");
      }
    }
    if (const auto i = FirstRepeat(p.values)) {
      r.Error(values[*i], vpath + "." + std::to_string(*i),
              "'" + p.values[*i] + "' is listed twice (each value is one point)");
    }
  } else if (const YAML::Node range = Child(node, "range"); range.IsDefined()) {
    p.kind = ParameterKind::kRange;
    ReadRange(range, JoinPath(path, "range"), r, p);
    if (const auto i = FirstRepeat(p.values)) {
      r.Error(range, JoinPath(path, "range"),
              "values " + std::to_string(*i - 1) + " and " + std::to_string(*i) +
                  " round to the same " + p.values[*i] +
                  " (12 significant digits): a smaller count or a wider range");
    }
  } else {
    p.kind = ParameterKind::kRandom;
    ReadRandom(Child(node, "random"), JoinPath(path, "random"), r, p);
  }
  for (const auto& other : spec.parameters) {
    if (other.path == p.path && !p.path.empty()) {
      r.Error(Child(node, "path"), JoinPath(path, "path"),
              "'" + p.path + "' is varied twice; give all its values in one parameter");
    }
  }
  spec.parameters.push_back(std::move(p));
}

// Issues about the key path itself, raised by loading the base scenario with
// one override: those make every run fail the same way, so the sweep file is
// wrong, not a run.
void CheckParameterPath(const SweepSpec& spec, const ParameterSpec& p, const YAML::Node& at,
                        const std::string& key_path, YamlReader& r) {
  std::vector<std::string> args = FixedOverrides(spec);
  const std::string probe =
      p.kind == ParameterKind::kRandom ? cosim::FormatValue(p.a) : p.values.front();
  args.push_back(p.path + "=" + probe);
  try {
    loader::LoadScenario(spec.scenario, args);
  } catch (const ScenarioError& e) {
    for (const Issue& i : e.issues()) {
      // At the path or on the way to it; an unknown key deeper down is in a
      // value (a map given as the value), which fails only its own run.
      const bool at_parameter = i.key_path == p.path || p.path.rfind(i.key_path + ".", 0) == 0;
      if (i.unknown_path && at_parameter) {
        r.Error(at, key_path, "not a setting of " + spec.scenario + ": " + i.message);
      }
    }
  }
}

// A unit parameter a sweep path names in the base scenario
// (units.NAME.parameters.KEY, or KEY.N for one element of a list) and
// declares a rule for.
struct RuledParameter {
  const cosim::Unit* unit = nullptr;
  const cosim::VariableInfo* info = nullptr;
  bool element = false;  // KEY.N: one number of a list
};

std::optional<RuledParameter> FindRuledParameter(const loader::Scenario& base,
                                                 const std::string& path) {
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t dot = path.find('.', start);
    parts.push_back(path.substr(start, dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  if ((parts.size() != 4 && parts.size() != 5) || parts[0] != "units" || parts[2] != "parameters" ||
      !base.system) {
    return std::nullopt;
  }
  const auto u = base.system->FindUnit(parts[1]);
  if (!u) return std::nullopt;
  const cosim::Unit& unit = base.system->unit(*u);
  const auto ref = unit.variables().Find(parts[3]);
  if (!ref) return std::nullopt;
  const cosim::VariableInfo& info = unit.variables().info(*ref);
  if (info.causality != cosim::Causality::kParameter || info.rule.empty()) return std::nullopt;
  if (parts.size() == 5) {
    const bool digits =
        !parts[4].empty() && parts[4].find_first_not_of("0123456789") == std::string::npos;
    if (info.type != cosim::VarType::kRealArray || !digits) return std::nullopt;
  }
  return RuledParameter{&unit, &info, parts.size() == 5};
}

// A sweep value as the unit would take it; nothing for one of another type
// (the run's loader reports that).
std::optional<cosim::Value> ValueOf(const YAML::Node& node, const RuledParameter& p) {
  const auto real = [&]() -> std::optional<cosim::Value> {
    if (const auto x = YamlReader::DecodeReal(node)) return *x;
    return std::nullopt;
  };
  switch (p.info->type) {
    case cosim::VarType::kReal:
      return real();
    case cosim::VarType::kRealArray: {
      if (p.element || !node.IsSequence()) return real();
      std::vector<double> list;
      for (const auto& item : node) {
        const auto x = YamlReader::DecodeReal(item);
        if (!x) return std::nullopt;
        list.push_back(*x);
      }
      return list;
    }
    case cosim::VarType::kInteger: {
      std::int64_t n = 0;
      if (node.IsScalar() && YAML::convert<std::int64_t>::decode(node, n)) return n;
      return std::nullopt;
    }
    case cosim::VarType::kString:
      if (node.IsScalar()) return node.Scalar();
      return std::nullopt;
    case cosim::VarType::kBoolean:
      break;
  }
  return std::nullopt;
}

// Refuses, at its key, a value the unit's declared rule refuses: every run
// with it would fail the same way before time zero.
void CheckValueAgainstRule(const ParameterSpec& spec, const RuledParameter& p,
                           const YAML::Node& node, const std::string& key_path, YamlReader& r) {
  const auto value = ValueOf(node, p);
  if (!value) return;
  for (const auto& problem : cosim::CheckRule(*p.info, *value)) {
    const std::string element = problem.index ? "." + std::to_string(*problem.index) : "";
    // "units.m.parameters.resistance.1: must be > 0, got -1 (the rule of
    // unit 'm' (dc_motor): > 0)".
    r.Error(problem.index ? node[*problem.index] : node, key_path + element,
            spec.path + element + ": " + problem.message + " (the rule of " + p.unit->Where() +
                ": " + p.info->rule.Text() + ")");
  }
}

// Every listed value, both ends of a range and the bounds of a bounded
// distribution of a unit parameter, against the rule the unit declares.
// (A rule is an interval or a set; the values of a range lie between its
// ends. A normal draw is unbounded: its mean is checked.)
void CheckParameterRule(const loader::Scenario& base, const ParameterSpec& p,
                        const YAML::Node& node, const std::string& path, YamlReader& r) {
  const auto ruled = FindRuledParameter(base, p.path);
  if (!ruled) return;
  const auto check = [&](const YAML::Node& at, const std::string& at_path) {
    CheckValueAgainstRule(p, *ruled, at, at_path, r);
  };
  switch (p.kind) {
    case ParameterKind::kValues: {
      const YAML::Node values = Child(node, "values");
      for (std::size_t i = 0; i < values.size(); ++i) {
        check(values[i], JoinPath(path, "values." + std::to_string(i)));
      }
      break;
    }
    case ParameterKind::kRange: {
      const YAML::Node range = Child(node, "range");
      for (const char* end : {"from", "to"}) {
        check(Child(range, end), JoinPath(path, std::string("range.") + end));
      }
      break;
    }
    case ParameterKind::kRandom: {
      const YAML::Node random = Child(node, "random");
      const std::vector<const char*> keys = p.distribution == Distribution::kNormal
                                                ? std::vector<const char*>{"mean"}
                                                : std::vector<const char*>{"min", "max"};
      for (const char* key : keys) {
        check(Child(random, key), JoinPath(path, std::string("random.") + key));
      }
      break;
    }
  }
}

}  // namespace

std::vector<std::string> FixedOverrides(const SweepSpec& spec) {
  std::vector<std::string> args;
  for (const auto& [path, value] : spec.fixed) args.push_back(path + "=" + value);
  return args;
}

SweepSpec RepeatSweepSpec(const std::string& scenario, const std::vector<std::string>& set_args,
                          std::int64_t runs) {
  if (runs < 2 || runs > 1000000) {
    throw std::invalid_argument("--runs " + std::to_string(runs) + ": expected 2 to 1000000");
  }
  SweepSpec spec;
  const config::InputFileRecord inputs;
  const loader::Scenario base = loader::LoadScenario(scenario, set_args);
  spec.inputs = inputs.files();
  spec.file = scenario;
  spec.scenario = scenario;
  spec.name = base.name;
  spec.description = base.description;
  spec.scenario_sha256 = base.sha256;
  for (const std::string& a : set_args) {
    const auto eq = a.find('=');
    // --set seed=N is the base the runs' seeds are derived from (base.seed
    // below); kept as a fixed setting it would give every run that one seed.
    if (a.substr(0, eq) == "seed") continue;
    spec.fixed.emplace_back(a.substr(0, eq), eq == std::string::npos ? "" : a.substr(eq + 1));
  }
  spec.repeats = runs;
  spec.seed = base.seed;
  spec.seeds = SeedPolicy::kPerRun;
  for (const auto& m : base.metrics) spec.metrics.push_back(m.name);
  if (spec.metrics.empty()) {
    throw ScenarioError({{scenario, 0, "metrics",
                          "the scenario defines no metrics, so repeated runs have nothing to "
                          "collect"}});
  }
  spec.reference = base.reference;
  return spec;
}

SweepSpec LoadSweepSpec(const std::string& file) {
  return LoadSweepSpecTree(loader::LoadYamlOrThrow(file, "sweep"), file);
}

SweepSpec LoadSweepSpecTree(const YAML::Node& root, const std::string& file) {
  SweepSpec spec;
  spec.file = file;
  YamlReader r(file);
  if (!r.ExpectMap(root, "")) throw ScenarioError(r.issues());
  r.CheckKeys(root, "",
              {"name", "description", "scenario", "set", "parameters", "combine", "samples",
               "repeats", "seed", "seeds", "metrics", "reference"});
  spec.name = r.String(root, "", "name", fs::path(file).stem().string());
  spec.description = r.String(root, "", "description", "");
  const std::string scenario = r.String(root, "", "scenario", std::nullopt);
  if (!scenario.empty()) {
    // Relative to the sweep file, so a sweep runs from any folder.
    const fs::path p(scenario);
    spec.scenario =
        p.is_absolute() ? scenario : (fs::path(file).parent_path() / p).lexically_normal().string();
  }
  if (const YAML::Node set = Child(root, "set"); set.IsDefined()) {
    if (r.ExpectMap(set, "set")) {
      for (const auto& kv : set) {
        const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
        if (!IsDottedPath(key)) {
          r.Error(kv.first, "set",
                  "expected dotted paths as keys, e.g. duration_s: 5, got " + Describe(kv.first));
          continue;
        }
        if (key == "seed") {
          r.Error(kv.first, "set.seed",
                  "each run's seed comes from the sweep (repeats:, seeds: and seed:), which "
                  "results.csv reports in its seed column: set the sweep's seed: instead");
          continue;
        }
        spec.fixed.emplace_back(key, YamlText(kv.second));
      }
    }
  }
  // Without parameters a sweep repeats the scenario as it is (repeats: N,
  // N >= 2, checked below): a repeatability study such as paper 2's 20 runs.
  const YAML::Node parameters = Child(root, "parameters");
  if (parameters.IsDefined() && r.ExpectSequence(parameters, "parameters")) {
    for (std::size_t i = 0; i < parameters.size(); ++i) {
      ReadParameter(parameters[i], "parameters." + std::to_string(i), r, spec);
    }
  }
  const std::string combine = r.String(root, "", "combine", "grid", {"grid", "monte_carlo"});
  spec.combination = combine == "monte_carlo" ? Combination::kMonteCarlo : Combination::kGrid;
  if (spec.combination == Combination::kMonteCarlo) {
    spec.samples = r.Integer(root, "", "samples", std::nullopt, 1, 100000000);
  } else {
    if (Child(root, "samples").IsDefined()) {
      r.Error(Child(root, "samples"), "samples",
              "samples are Monte-Carlo draws: set combine: monte_carlo, or leave samples out");
    }
    for (std::size_t i = 0; i < spec.parameters.size(); ++i) {
      if (spec.parameters[i].kind == ParameterKind::kRandom) {
        r.Error(parameters[i], "parameters." + std::to_string(i) + ".random",
                "random draws need combine: monte_carlo (a grid takes values or a range)");
      }
    }
  }
  spec.repeats = r.Integer(root, "", "repeats", 1, 1, 1000000);
  if (spec.parameters.empty() && spec.repeats < 2 &&
      (!parameters.IsDefined() || parameters.IsSequence())) {
    r.Error(parameters.IsDefined() ? parameters : root, "parameters",
            "expected at least one parameter to vary, or repeats: N (N >= 2) to run the "
            "scenario as it is N times");
  }
  // Points x samples x repeats, refused above kMaxRuns before it could
  // overflow: each run is a row, and the ids of the runs to do are held.
  double runs = static_cast<double>(spec.samples) * static_cast<double>(spec.repeats);
  for (const auto& p : spec.parameters) {
    if (p.kind != ParameterKind::kRandom)
      runs *= static_cast<double>(std::max<std::size_t>(1, p.values.size()));
  }
  if (runs > static_cast<double>(kMaxRuns)) {
    r.Error(parameters, "parameters",
            "the sweep has " + cosim::FormatValue(runs) +
                " runs (points x samples x repeats); at most " + std::to_string(kMaxRuns) +
                " are allowed: split it into several sweeps");
  }
  spec.seed = static_cast<std::uint64_t>(
      r.Integer(root, "", "seed", 1, 0, std::numeric_limits<std::int64_t>::max()));
  spec.seeds = r.String(root, "", "seeds", "common", {"common", "per_run"}) == "per_run"
                   ? SeedPolicy::kPerRun
                   : SeedPolicy::kCommon;
  const YAML::Node metrics = Child(root, "metrics");
  if (metrics.IsDefined() && r.ExpectSequence(metrics, "metrics")) {
    for (std::size_t i = 0; i < metrics.size(); ++i) {
      if (auto m = r.AsString(metrics[i], "metrics." + std::to_string(i))) {
        spec.metrics.push_back(*m);
      }
    }
  }
  spec.reference = loader::ReadReference(Child(root, "reference"), r);
  if (!r.ok()) throw ScenarioError(r.issues());

  // The base scenario with the fixed settings must load by itself. Every
  // file it reads (and the parameter checks' loads read) is one the runs
  // depend on: spec.inputs.
  const config::InputFileRecord inputs;
  loader::Scenario base;
  try {
    base = loader::LoadScenario(spec.scenario, FixedOverrides(spec));
  } catch (const ScenarioError& e) {
    std::vector<Issue> issues{{file, YamlReader::LineOf(Child(root, "scenario")), "scenario",
                               "the base scenario " + spec.scenario +
                                   (spec.fixed.empty() ? "" : " with the settings under set:") +
                                   " is refused:"}};
    issues.insert(issues.end(), e.issues().begin(), e.issues().end());
    throw ScenarioError(issues);
  }
  spec.scenario_sha256 = base.sha256;
  std::vector<std::string> defined;
  for (const auto& m : base.metrics) defined.push_back(m.name);
  if (spec.metrics.empty()) spec.metrics = defined;
  for (std::size_t i = 0; i < spec.metrics.size(); ++i) {
    if (std::find(defined.begin(), defined.end(), spec.metrics[i]) == defined.end()) {
      r.Error(metrics[i], "metrics." + std::to_string(i),
              "'" + spec.metrics[i] + "' is not a metric of " + spec.scenario +
                  (defined.empty() ? " (it defines none)"
                                   : "; it defines: " + config::JoinNames(defined)));
    }
  }
  if (const auto i = FirstRepeat(spec.metrics); i && metrics.IsDefined()) {
    r.Error(metrics[*i], "metrics." + std::to_string(*i),
            "'" + spec.metrics[*i] + "' is listed twice");
  }
  const std::vector<std::string> header = ResultsHeader(spec);
  for (std::size_t i = 0; i < spec.metrics.size(); ++i) {
    const std::string& m = spec.metrics[i];
    if (std::count(header.begin(), header.end(), m) > 1) {
      r.Error(metrics.IsDefined() ? metrics[i] : root, "metrics." + std::to_string(i),
              "'" + m +
                  "' is also the name of another column of results.csv; rename the metric "
                  "in the scenario");
    }
  }
  if (spec.reference.title.empty() && spec.parameters.empty()) {
    // Repeats of the scenario as it is: its reference, for the metrics this
    // sweep collects (a sweep that varies it is not what the source ran).
    spec.reference.title = base.reference.title;
    for (const auto& m : base.reference.metrics) {
      if (std::find(spec.metrics.begin(), spec.metrics.end(), m.metric) != spec.metrics.end()) {
        spec.reference.metrics.push_back(m);
      }
    }
    if (spec.reference.metrics.empty()) spec.reference.title.clear();
  } else {
    loader::CheckReferenceMetrics(spec.reference, spec.metrics, root, "this sweep collects", r);
  }
  if (spec.metrics.empty() && r.ok()) {
    r.Error(root, "metrics",
            "the base scenario defines no metrics, so a sweep has nothing to collect");
  }
  for (std::size_t i = 0; i < spec.parameters.size(); ++i) {
    const std::string path = "parameters." + std::to_string(i) + ".path";
    CheckParameterPath(spec, spec.parameters[i], Child(parameters[i], "path"), path, r);
    CheckParameterRule(base, spec.parameters[i], parameters[i], "parameters." + std::to_string(i),
                       r);
  }
  if (!r.ok()) throw ScenarioError(r.issues());
  spec.inputs = inputs.files();
  return spec;
}

}  // namespace linesim::sweep
