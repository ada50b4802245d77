#include "app/commands.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "app/console.h"
#include "config/unit_registry.h"
#include "cosim/variable_rows.h"
#include "loader/scenario.h"
#include "session/run_folder.h"
#include "session/session.h"
#include "units/fmu/fmu_unit.h"

namespace linesim::app {

namespace fs = std::filesystem;

namespace {

// The variable table as aligned columns (cosim/variable_rows.h), "-" for
// an empty unit or rule, the direct dependencies after the description.
constexpr int kTableColumns = 7;
using TableRow = std::array<std::string, kTableColumns>;

std::vector<TableRow> TableRows(const cosim::Unit& unit) {
  std::vector<TableRow> rows{{"name", "causality", "type", "unit", "start", "rule", "description"}};
  for (const auto& v : cosim::VariableRows(unit)) {
    std::string description = v.description;
    if (!v.depends_on.empty()) {
      description += " [depends directly on:";
      for (const auto& name : v.depends_on) description += " " + name;
      description += "]";
    }
    rows.push_back({v.name, v.causality, v.type, v.unit.empty() ? "-" : v.unit, v.start,
                    v.rule.empty() ? "-" : v.rule, description});
  }
  return rows;
}

void PrintTable(const cosim::Unit& unit, std::ostream& out) {
  const std::vector<TableRow> rows = TableRows(unit);
  std::size_t width[kTableColumns - 1] = {};
  for (const auto& r : rows) {
    for (int c = 0; c + 1 < kTableColumns; ++c) width[c] = std::max(width[c], r[c].size());
  }
  for (const auto& r : rows) {
    out << "  ";
    for (int c = 0; c + 1 < kTableColumns; ++c)
      out << std::left << std::setw(static_cast<int>(width[c]) + 2) << r[c];
    out << r[kTableColumns - 1] << "\n";
  }
}

// A table cell in Markdown: a '|' would end the cell.
std::string MarkdownCell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

void PrintMarkdownTable(const cosim::Unit& unit, std::ostream& out) {
  const std::vector<TableRow> rows = TableRows(unit);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    out << "|";
    for (const auto& cell : rows[i]) out << " " << MarkdownCell(cell) << " |";
    out << "\n";
    if (i == 0) out << "|---|---|---|---|---|---|---|\n";
  }
}

}  // namespace

int RunCommand(const std::string& file, const std::string& out_dir,
               const std::vector<std::string>& set_args, double max_output_mb,
               plots::PlotFormat format, RunColumns* plot_columns, bool replay,
               bool write_mcap) {
  if (IsComparisonFile(file)) {
    if (write_mcap) {
      std::cerr << "linesim: " << file
                << ": --mcap writes the log of one run; a comparison file (compare:) runs "
                   "several: run the one you want to see as a scenario with --mcap\n";
      return kExitBadInput;
    }
    return CompareCommand(file, out_dir, set_args, max_output_mb, format);
  }
  std::optional<session::Session> run;
  try {
    run.emplace(file, set_args);
  } catch (const config::ScenarioError& e) {
    PrintIssues(e, "scenario", std::cerr);
    return kExitBadInput;
  }
  const loader::Scenario& s = run->scenario();
  session::FolderOptions options;
  options.max_output_mb = max_output_mb;
  options.format = format;
  options.replay = replay;
  options.mcap = write_mcap;
  // Ctrl-C or SIGTERM: stop at the next communication point, keep what was
  // recorded and write the summary (status interrupted); again to quit.
  std::atomic<bool>& stop = InstallStopSignals(
      "\nlinesim: interrupted: stopping at the next communication point (again to quit at "
      "once)\n");
  session::FolderRun written;
  try {
    written = session::RunIntoFolder(*run, file, out_dir, options, &stop);
  } catch (const session::OutputError& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    return kExitBadInput;
  }
  const session::RunReport& report = written.report;
  // Every file that could not be written is named, also when the summary
  // that lists them is one of them (a full disk).
  for (const auto& w : written.warnings) std::cerr << "linesim: " << w << "\n";
  if (!written.summary_error.empty()) {
    for (const auto& e : report.errors) std::cerr << "linesim: " << e.message << "\n";
    std::cerr << "linesim: " << written.summary_error << "\n";
    return kExitRunFailed;
  }
  const cosim::RunResult& result = report.result;
  const fs::path dir(out_dir);
  const cosim::MasterOptions& master = s.master->options();
  const double simulated_s = cosim::NsToSeconds(result.end_time - master.start);

  std::cout << s.name << ": "
            << (report.interrupted ? "INTERRUPTED"
                : report.ok()      ? "ok"
                                   : "FAILED")
            << ", " << cosim::FormatSeconds(result.end_time - master.start) << " s simulated in "
            << std::setprecision(3) << report.wall_s << " s wall (" << std::setprecision(4)
            << simulated_s / report.wall_s << "x real time)\n";
  if (!result.ended_by.empty()) std::cout << "  ended early by " << result.ended_by << "\n";
  std::size_t name_width = 0;
  for (const auto& [name, value] : report.metrics) name_width = std::max(name_width, name.size());
  for (const auto& [name, value] : report.metrics) {
    std::cout << "  " << std::left << std::setw(static_cast<int>(name_width)) << name << " = "
              << std::setprecision(6) << value << "\n";
  }
  std::cout << "  wrote " << (dir / "summary.json").string() << ", "
            << (dir / "signals.csv").string() << " (" << written.rows << " rows)";
  for (const auto& p : written.files) std::cout << ", " << p;
  if (written.mcap) std::cout << ", run.mcap";
  std::cout << "\n";
  for (const auto& e : report.errors) std::cerr << "linesim: " << e.message << "\n";
  for (const auto& w : report.warnings) std::cerr << "linesim: warning: " << w << "\n";
  if (plot_columns && s.robot) {
    plot_columns->error_column = s.robot->error_column;
    plot_columns->belt_on_columns = s.robot->belt_on_columns;
    plot_columns->task = s.robot->task;
    plot_columns->bound = s.robot->figure_bound;
  }
  if (report.interrupted) return kExitInterrupted;
  return report.ok() ? kExitOk : kExitRunFailed;
}

// `linesim inspect X.fmu`: what the FMU declares and what the `fmu` unit
// makes of it.
static int InspectFmu(const std::string& file) {
  std::unique_ptr<fmu::FmuUnit> unit;
  try {
    unit = std::make_unique<fmu::FmuUnit>("fmu", file);
  } catch (const std::exception& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    return kExitBadInput;
  }
  const fmu::ModelDescription& md = unit->description();
  const auto yes = [](bool b) { return b ? "yes" : "no"; };
  const auto seconds = [](const std::optional<double>& v) {
    return v ? cosim::FormatValue(*v) + " s" : std::string("-");
  };
  std::cout << "FMU " << file << ": FMI " << md.fmi_version << " co-simulation, model '"
            << md.model_name << "' (modelIdentifier " << md.model_identifier << ")\n";
  if (!md.description.empty()) std::cout << "  description:      " << md.description << "\n";
  std::cout << "  generation tool:  " << (md.generation_tool.empty() ? "-" : md.generation_tool);
  if (!md.generation_date.empty()) std::cout << " (" << md.generation_date << ")";
  std::cout << "\n  token:            " << md.token << "\n";
  std::cout << "  capabilities:     canGetAndSetFMUstate " << yes(md.can_get_and_set_state)
            << ", canSerializeFMUstate " << yes(md.can_serialize_state)
            << ", canHandleVariableCommunicationStepSize " << yes(md.can_handle_variable_step);
  if (md.fmi_major == 2) {
    std::cout << ", canInterpolateInputs " << yes(md.can_interpolate_inputs);
  } else {
    std::cout << ", mightReturnEarlyFromDoStep " << yes(md.can_return_early)
              << ", fixedInternalStepSize " << seconds(md.fixed_internal_step);
  }
  std::cout << ", needsExecutionTool " << yes(md.needs_execution_tool)
            << ", canBeInstantiatedOnlyOncePerProcess " << yes(md.only_once_per_process);
  if (md.has_model_exchange) std::cout << " (also model exchange: not used)";
  std::cout << "\n  default experiment: start " << seconds(md.default_start) << ", stop "
            << seconds(md.default_stop) << ", step " << seconds(md.default_step)
            << ", tolerance "
            << (md.default_tolerance ? cosim::FormatValue(*md.default_tolerance) : "-") << "\n";
  std::cout << "variables, as a unit `type: fmu` with `parameters: {path: ...}` declares them:\n";
  PrintTable(*unit, std::cout);
  std::string left_out;
  for (const auto& m : unit->mapping()) {
    if (!m.mapped) left_out += (left_out.empty() ? "" : ", ") + m.fmi_name;
  }
  if (!left_out.empty()) {
    std::cout << "left out (inside the FMU only: the independent time, non-Real locals): "
              << left_out << "\n";
  }
  return kExitOk;
}

int UnitReferenceCommand() {
  std::cout << "# Unit types\n\n"
               "Every unit type linesim registers, with its variables as `linesim inspect TYPE`\n"
               "prints them. Generated: `build/app/linesim inspect --all > docs/units.md`\n"
               "(test `UnitReference.DocsUnitsMdIsCurrent` fails when it is stale).\n"
               "How units are used in scenario files: `docs/scenarios.md`.\n";
  for (const auto& type : config::UnitTypes()) {
    std::cout << "\n## `" << type.name << "`\n\n" << type.description << "\n";
    if (!type.model_folder.empty()) {
      std::cout << "\nModel files (`parameters.model`): `models/" << type.model_folder << "/`.\n";
    }
    if (!type.structural_keys.empty()) {
      std::cout << "\nKeys under `parameters:` that shape the unit:\n\n";
      for (const auto& k : type.structural_keys) {
        std::cout << "- `" << k.name << "`: " << k.description << "\n";
      }
    }
    std::unique_ptr<cosim::Unit> unit;
    try {
      unit = loader::CreateDefaultUnit(type);
    } catch (const config::ScenarioError& e) {
      std::cerr << "linesim: " << e.what() << "\n";
      return kExitBadInput;
    }
    std::cout << "\n";
    PrintMarkdownTable(*unit, std::cout);
  }
  return kExitOk;
}

int InspectCommand(const std::string& what, const std::vector<std::string>& set_args) {
  if (what.ends_with(".fmu") && config::FindUnitType(what) == nullptr) {
    if (!set_args.empty()) {
      std::cerr << "linesim: --set applies to a scenario file, not to an FMU\n";
      return kExitBadInput;
    }
    return InspectFmu(what);
  }
  // A type name first: a file or folder of that name where linesim runs
  // (inspect chassis from inside units/) does not hide the type.
  const config::UnitType* type = config::FindUnitType(what);
  std::error_code ec;
  const bool is_file =
      !type && (fs::exists(what, ec) || what.ends_with(".yaml") || what.ends_with(".yml"));
  if (!is_file) {
    if (!set_args.empty()) {
      std::cerr << "linesim: --set applies to a scenario file, not to a unit type\n";
      return kExitBadInput;
    }
    if (!type) {
      std::cerr << "linesim: " << config::UnknownTypeMessage(what) << "\n";
      return kExitBadInput;
    }
    std::unique_ptr<cosim::Unit> unit;
    try {
      unit = loader::CreateDefaultUnit(*type);
    } catch (const config::ScenarioError& e) {
      std::cerr << "linesim: " << e.what() << "\n";
      return kExitBadInput;
    }
    std::cout << "unit type '" << type->name << "': " << type->description << "\n";
    std::cout << "keys under parameters: that shape the unit:\n";
    std::size_t key_width = 0;
    for (const auto& k : type->structural_keys) key_width = std::max(key_width, k.name.size());
    for (const auto& k : type->structural_keys) {
      std::cout << "  " << std::left << std::setw(static_cast<int>(key_width)) << k.name << "  "
                << k.description << "\n";
    }
    std::cout << "variables (with the default keys above):\n";
    PrintTable(*unit, std::cout);
    return kExitOk;
  }

  loader::Scenario s;
  try {
    s = loader::LoadScenario(what, set_args);
  } catch (const config::ScenarioError& e) {
    PrintIssues(e, "scenario", std::cerr);
    return kExitBadInput;
  }
  const auto& o = s.master->options();
  std::cout << "scenario '" << s.name << "' (" << what << ")";
  if (!s.description.empty()) std::cout << ": " << s.description;
  std::cout << "\n  duration " << cosim::FormatSeconds(o.stop - o.start) << " s, seed " << s.seed
            << ", master " << cosim::ToString(o.algorithm) << " step "
            << cosim::FormatSeconds(o.base_step) << " s";
  if (o.retry.enabled) {
    std::cout << ", retry on (min step " << cosim::FormatSeconds(o.retry.min_step)
              << " s, shrink " << o.retry.shrink << ", grow " << o.retry.grow << ")";
  }
  std::cout << "\n";
  if (s.robot) {
    // The robot-level file and what it stands for, in the system-level
    // format (a file of its own could be run as is).
    YAML::Emitter yaml;
    yaml << s.expanded;
    std::cout << "\nexpands into this system:\n" << yaml.c_str() << "\n";
  }
  const cosim::System& system = *s.system;
  for (std::size_t u = 0; u < system.unit_count(); ++u) {
    std::cout << "\nunit '" << system.unit(u).name() << "' (" << system.unit(u).type_name()
              << ", step " << cosim::FormatSeconds(o.base_step * s.master->decimation(u))
              << " s)\n";
    PrintTable(system.unit(u), std::cout);
  }
  std::cout << "\nconnections:\n";
  for (const auto& c : system.connections()) {
    std::cout << "  " << c.from.ToString() << " -> " << c.to.ToString() << "\n";
  }
  std::cout << "\nstep order (Gauss-Seidel):";
  for (std::size_t u : system.dependency_order()) std::cout << " " << system.unit(u).name();
  std::cout << "\n";
  return kExitOk;
}

}  // namespace linesim::app
