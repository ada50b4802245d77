// `linesim run COMPARE.yaml`: one scenario run several ways, and their
// deviations over time in one figure (paper 1 Fig. 6: the nominal system
// beside the modified one).

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>

#include "app/commands.h"
#include "app/console.h"
#include "config/scenario_error.h"
#include "cosim/files.h"
#include "loader/scenario.h"
#include "plots/compare_plots.h"
#include "session/session.h"

namespace linesim::app {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

struct CompareRun {
  std::string name, label;
  std::vector<std::string> sets;  // path=value, the run's own
};

struct Comparison {
  std::string name, description, scenario;
  std::vector<CompareRun> runs;
};

// A run's folder name: at most NAME_MAX (255 bytes on Linux's file
// systems) of [A-Za-z0-9._-], not "." or "..".
constexpr std::size_t kMaxFolderName = 255;

bool SafeName(const std::string& name) {
  if (name.empty() || name == "." || name == ".." || name.size() > kMaxFolderName) return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

// A value of `set:` as --set takes it: a scalar as written, anything else
// in YAML's flow style.
std::string ValueText(const YAML::Node& v) {
  if (v.IsScalar()) return v.Scalar();
  if (v.IsNull()) return "null";
  YAML::Emitter out;
  out.SetMapFormat(YAML::Flow);
  out.SetSeqFormat(YAML::Flow);
  out << v;
  return out.c_str();
}

// Reads and checks the comparison file; every problem at once.
Comparison ReadComparison(const std::string& file) {
  std::vector<config::Issue> issues;
  const auto issue = [&](const YAML::Node& at, const std::string& path, const std::string& what) {
    issues.push_back({file, at.IsDefined() ? at.Mark().line + 1 : 0, path, what});
  };
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const std::exception& e) {
    throw config::ScenarioError({{file, 0, "", std::string("cannot read it: ") + e.what()}});
  }
  Comparison c;
  if (!root.IsMap()) throw config::ScenarioError({{file, 0, "", "expected a map"}});
  for (const auto& kv : root) {
    const std::string key = kv.first.Scalar();
    if (key != "name" && key != "description" && key != "compare" && key != "runs") {
      issue(kv.first, key, "unknown key (a comparison has name, description, compare, runs)");
    }
  }
  const auto text = [&](const YAML::Node& parent, const std::string& path, const char* key,
                        bool required) {
    const YAML::Node v = parent[key];
    if (!v.IsDefined()) {
      if (required) issue(parent, path.empty() ? key : path + "." + key, "required");
      return std::string();
    }
    if (!v.IsScalar() || v.Scalar().empty()) {
      issue(v, path.empty() ? key : path + "." + key, "expected a text");
      return std::string();
    }
    return v.Scalar();
  };
  c.name = text(root, "", "name", true);
  c.description = text(root, "", "description", false);
  const std::string base = text(root, "", "compare", true);
  if (!base.empty()) c.scenario = (fs::path(file).parent_path() / base).lexically_normal().string();
  const YAML::Node runs = root["runs"];
  if (!runs.IsDefined() || !runs.IsSequence() || runs.size() < 2) {
    issue(runs.IsDefined() ? runs : root, "runs",
          "expected a list of at least two runs ({name, label, set})");
  } else {
    std::set<std::string> names;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const std::string path = "runs." + std::to_string(i);
      const YAML::Node r = runs[i];
      if (!r.IsMap()) {
        issue(r, path, "expected a map {name, label, set}");
        continue;
      }
      for (const auto& kv : r) {
        const std::string key = kv.first.Scalar();
        if (key != "name" && key != "label" && key != "set") {
          issue(kv.first, path + "." + key, "unknown key (a run has name, label, set)");
        }
      }
      CompareRun run;
      run.name = text(r, path, "name", true);
      if (!run.name.empty() && !SafeName(run.name)) {
        issue(r["name"], path + ".name",
              "expected a folder name of at most " + std::to_string(kMaxFolderName) +
                  " characters of [A-Za-z0-9._-], got '" + run.name + "'");
      } else if (!run.name.empty() && !names.insert(run.name).second) {
        issue(r["name"], path + ".name", "'" + run.name + "' names two runs");
      }
      run.label = text(r, path, "label", false);
      if (run.label.empty()) run.label = run.name;
      const YAML::Node set = r["set"];
      if (set.IsDefined() && !set.IsNull()) {
        if (!set.IsMap()) {
          issue(set, path + ".set", "expected a map of dotted.path: value");
        } else {
          for (const auto& kv : set) run.sets.push_back(kv.first.Scalar() + "=" + ValueText(kv.second));
        }
      }
      c.runs.push_back(std::move(run));
    }
  }
  if (!issues.empty()) throw config::ScenarioError(std::move(issues));
  return c;
}

}  // namespace

bool IsComparisonFile(const std::string& file) {
  try {
    const YAML::Node root = YAML::LoadFile(file);
    return root.IsMap() && root["compare"].IsDefined();
  } catch (const std::exception&) {
    return false;  // the scenario loader says what is wrong with it
  }
}

int CompareCommand(const std::string& file, const std::string& out_dir,
                   const std::vector<std::string>& set_args, double max_output_mb,
                   plots::PlotFormat format) {
  Comparison c;
  try {
    c = ReadComparison(file);
    // Every run's scenario is checked before anything runs.
    for (const CompareRun& run : c.runs) {
      std::vector<std::string> sets = run.sets;
      sets.insert(sets.end(), set_args.begin(), set_args.end());
      const loader::Scenario s = loader::LoadScenario(c.scenario, sets);
      if (!s.robot) {
        throw config::ScenarioError(
            {{file, 0, "compare", "'" + c.scenario + "' is not a robot scenario: a comparison "
                                  "draws robot runs' deviations"}});
      }
    }
  } catch (const config::ScenarioError& e) {
    PrintIssues(e, "comparison", std::cerr);
    return kExitBadInput;
  }
  if (!CreateOutputFolder(out_dir)) return kExitBadInput;
  const fs::path dir(out_dir);
  plots::ComparisonPlotSpec spec;
  spec.run_caption = c.description.empty() ? c.name : c.description + " (" + c.name + ")";
  spec.format = format;
  Json summary;
  summary["comparison"] = c.name;
  summary["file"] = file;
  summary["scenario"] = c.scenario;
  Json runs = Json::array();
  int status = kExitOk;
  for (const CompareRun& run : c.runs) {
    std::vector<std::string> sets = run.sets;
    sets.insert(sets.end(), set_args.begin(), set_args.end());
    std::cout << "== " << run.name << " (" << run.label << ")\n";
    RunColumns columns;
    const int one = RunCommand(c.scenario, (dir / run.name).string(), sets, max_output_mb, format,
                               &columns);
    if (one == kExitInterrupted || one == kExitBadInput) return one;
    if (one != kExitOk) status = kExitRunFailed;
    Json entry;
    entry["name"] = run.name;
    entry["label"] = run.label;
    Json overrides = Json::array();
    for (const auto& o : sets) overrides.push_back(o);
    entry["overrides"] = overrides;
    entry["status"] = one == kExitOk ? "ok" : "failed";
    std::ifstream in(dir / run.name / "summary.json");
    const Json run_summary = Json::parse(in, nullptr, false);
    entry["metrics"] = run_summary.is_object() && run_summary.contains("metrics")
                           ? run_summary["metrics"]
                           : Json(nullptr);
    runs.push_back(entry);
    if (columns.error_column.empty()) continue;
    if (spec.runs.empty()) {
      spec.belt_on_columns = columns.belt_on_columns;
      spec.error_label =
          columns.task == "hold" ? "drift from the held position" : "deviation from the path";
      // The compared scenario's published bound (its figures.bound).
      spec.bound_m = columns.bound.value_m;
      spec.bound_label = columns.bound.label;
    }
    spec.runs.push_back({run.name + "/signals.csv", columns.error_column, run.label});
  }
  summary["runs"] = runs;
  try {
    const std::string picture = plots::WriteComparisonPlot(dir.string(), spec);
    summary["plots"] = {{"files", {fs::path(picture).filename().string()}}};
    std::cout << "wrote " << picture << "\n";
  } catch (const std::exception& e) {
    summary["plots"] = {{"error", e.what()}};
    std::cerr << "linesim: no comparison plot: " << e.what() << "\n";
  }
  try {
    cosim::WriteFileAtomically((dir / "summary.json").string(), summary.dump(2) + "\n");
  } catch (const std::exception& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    return kExitRunFailed;
  }
  return status;
}

}  // namespace linesim::app
