#include "fmu_export/exporter.h"

#include <yaml-cpp/yaml.h>
#include <zip.h>

#include <stdlib.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "config/scenario_error.h"
#include "config/unit_registry.h"
#include "cosim/system.h"
#include "fmu_export/export_layout.h"
#include "fmu_export/model_description_writer.h"
#include "loader/overrides.h"
#include "loader/scenario.h"
#include "loader/yaml_files.h"
#include "models/models_dir.h"

namespace linesim::fmu_export {

namespace fs = std::filesystem;

namespace {

// A scratch folder removed with the object.
class Scratch {
 public:
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "linesim-export-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw ExportError("cannot make a temporary folder under " +
                        fs::temp_directory_path().string());
    }
    path_ = pattern;
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void WriteFile(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw ExportError("cannot write " + file.string());
}

// A parameter's value as YAML (numbers as the shortest text that reads back
// to the same double, so the FMU builds the identical unit).
YAML::Node ValueNode(const cosim::Value& v) {
  if (const auto* d = std::get_if<double>(&v)) return YAML::Node(cosim::FormatValue(*d));
  if (const auto* i = std::get_if<std::int64_t>(&v)) return YAML::Node(std::to_string(*i));
  if (const auto* b = std::get_if<bool>(&v)) return YAML::Node(*b ? "true" : "false");
  if (const auto* s = std::get_if<std::string>(&v)) return YAML::Node(*s);
  YAML::Node list(YAML::NodeType::Sequence);
  for (double x : std::get<std::vector<double>>(v)) list.push_back(cosim::FormatValue(x));
  list.SetStyle(YAML::EmitterStyle::Flow);
  return list;
}

std::string Emit(const YAML::Node& node) {
  YAML::Emitter e;
  e << node;
  return std::string(e.c_str()) + "\n";
}

// The scenario's issues with "units.T.parameters.k" written as "--set k".
std::string Describe(const config::ScenarioError& e, const std::string& instance) {
  const std::string prefix = "units." + instance + ".parameters.";
  std::ostringstream out;
  for (const auto& issue : e.issues()) {
    std::string where = issue.key_path;
    if (where.rfind(prefix, 0) == 0) {
      // "mount_x.0": element 0 of an array, which --set gives whole.
      std::string key = where.substr(prefix.size());
      if (const auto dot = key.find('.'); dot != std::string::npos) {
        key = key.substr(0, dot) + " (element " + key.substr(dot + 1) + ")";
      }
      where = "--set " + key;
    } else if (!issue.file.empty() && issue.file.find("linesim-export-") == std::string::npos) {
      where = issue.file + (issue.line > 0 ? ":" + std::to_string(issue.line) : "") +
              (where.empty() ? "" : " " + where);
    }
    out << "\n  " << (where.empty() ? "" : where + ": ") << issue.message;
  }
  return out.str();
}

void AddBuffer(zip_t* zip, const std::string& name, const std::string& text) {
  // libzip copies nothing until zip_close: the text must outlive the archive
  // handle, so a copy is handed over with freep = 1.
  void* copy = std::malloc(text.size() ? text.size() : 1);
  if (!copy) throw ExportError("out of memory");
  std::memcpy(copy, text.data(), text.size());
  zip_source_t* src = zip_source_buffer(zip, copy, text.size(), 1);
  if (!src || zip_file_add(zip, name.c_str(), src, ZIP_FL_OVERWRITE | ZIP_FL_ENC_UTF_8) < 0) {
    if (src) zip_source_free(src);
    throw ExportError("cannot add " + name + " to the FMU: " + zip_strerror(zip));
  }
}

// The FMU's unit is built at fmi2Instantiate from the resource file alone:
// a type that builds without parameters (linesim inspect's placeholder of a
// structural key, a safety_field's one field set) may need values it was
// not given. Built here as the runtime will build it, so that an FMU that
// could not instantiate is never written.
void RefuseUnbuildableResource(const fs::path& scratch, const std::string& resource,
                               const std::string& scene_text, const std::string& instance,
                               const std::string& type) {
  const fs::path folder = scratch / "resources";
  fs::create_directories(folder);
  WriteFile(folder / kResourceFile, resource);
  if (!scene_text.empty()) WriteFile(folder / kSceneFile, scene_text);
  try {
    loader::LoadScenario((folder / kResourceFile).string());
  } catch (const config::ScenarioError& e) {
    throw ExportError("a " + type + " unit needs values to be built (give them with --set):" +
                      Describe(e, instance));
  }
}

}  // namespace

std::string RuntimeLibraryPath() {
  // An installed linesim's (lib/linesim/ beside bin/), else the build tree's.
  const std::string installed = models::InstalledPath(LINESIM_FMU_RUNTIME_FROM_BINDIR);
  return installed.empty() ? std::string(LINESIM_FMU_RUNTIME) : installed;
}

ExportResult ExportFmu(const ExportOptions& o) {
  const config::UnitType* type = config::FindUnitType(o.type);
  if (!type) throw ExportError(config::UnknownTypeMessage(o.type));
  if (o.type == "fmu") {
    throw ExportError("type fmu wraps an FMU that exists already: ship that FMU itself");
  }
  if (o.out.size() <= 4 || !o.out.ends_with(".fmu")) {
    throw ExportError("--out must name a .fmu file, got '" + o.out + "'");
  }
  const std::string runtime = o.runtime_library.empty() ? RuntimeLibraryPath() : o.runtime_library;
  if (!fs::is_regular_file(runtime)) {
    throw ExportError("the FMU runtime library " + runtime +
                      " is missing (build the target linesim_fmu_runtime)");
  }

  // The unit's parameters from --set, as a scenario would give them.
  YAML::Node params(YAML::NodeType::Map);
  for (const auto& text : o.sets) {
    loader::Override ov;
    try {
      ov = loader::ParseOverride(text);
    } catch (const config::ScenarioError& e) {
      throw ExportError("--set " + text + ": expected key=value");
    }
    if (ov.path.find('.') != std::string::npos) {
      throw ExportError("--set " + text + ": a key of the unit's parameters, not a dotted path");
    }
    YAML::Node value;
    try {
      value = YAML::Load(ov.value);
    } catch (const YAML::Exception& e) {
      throw ExportError("--set " + text + ": " + e.what());
    }
    // A model given as a path is relative to where linesim runs.
    if (ov.path == "model" && value.IsScalar()) {
      const std::string v = value.Scalar();
      if ((v.find('/') != std::string::npos || v.ends_with(".yaml")) && fs::path(v).is_relative()) {
        value = YAML::Node(fs::absolute(v).lexically_normal().string());
      }
    }
    params[ov.path] = value;
  }

  const std::string instance = type->name;
  Scratch scratch;
  YAML::Node scenario(YAML::NodeType::Map);
  scenario["name"] = type->name;
  scenario["description"] = "the linesim unit type " + type->name + " exported as an FMU";
  scenario["duration_s"] = "1";
  scenario["seed"] = "1";
  YAML::Node spec(YAML::NodeType::Map);
  spec["type"] = type->name;
  if (params.size() > 0) spec["parameters"] = params;
  scenario["units"][instance] = spec;
  if (!o.scene.empty()) {
    std::string scene = o.scene;
    if ((scene.find('/') != std::string::npos || scene.ends_with(".yaml")) &&
        fs::path(scene).is_relative()) {
      scene = fs::absolute(scene).lexically_normal().string();
    }
    scenario["scene"]["model"] = scene;
  }
  const fs::path draft = scratch.path() / "draft.yaml";
  WriteFile(draft, Emit(scenario));

  loader::Scenario s;
  try {
    s = loader::LoadScenario(draft.string());
  } catch (const config::ScenarioError& e) {
    throw ExportError("cannot build a " + type->name + " unit:" + Describe(e, instance));
  }
  const cosim::Unit& unit = s.system->unit(0);
  std::string scene_text;
  if (!o.scene.empty()) {
    std::ifstream in(s.scene.file, std::ios::binary);
    std::ostringstream buffer;
    buffer << in.rdbuf();
    scene_text = buffer.str();
    if (!in || scene_text.empty()) throw ExportError("cannot read the scene file " + s.scene.file);
  }

  // Structural keys: the --set value, else the model file's.
  YAML::Node model;
  if (params["model"] && !type->model_folder.empty()) {
    config::YamlReader reader(draft.string());
    model = loader::LoadModel(reader, params["model"], "model", "model", params["model"].Scalar(),
                              type->model_folder, draft.string());
  }
  YAML::Node resource_params(YAML::NodeType::Map);
  for (const auto& key : type->structural_keys) {
    if (key.name == "model") continue;
    if (params[key.name]) {
      resource_params[key.name] = params[key.name];
    } else if (model.IsMap() && model[key.name]) {
      resource_params[key.name] = model[key.name];
    }
  }
  // Every parameter with the value the unit holds (from its defaults, the
  // model file and --set): the FMU needs no model file.
  for (const auto& info : unit.variables().infos()) {
    if (info.causality != cosim::Causality::kParameter) continue;
    if (info.variability == cosim::Variability::kConstant) continue;
    resource_params[info.name] = ValueNode(unit.variables().GetValue(info.ref));
  }
  YAML::Node resource_spec(YAML::NodeType::Map);
  resource_spec["type"] = type->name;
  if (resource_params.size() > 0) resource_spec["parameters"] = resource_params;
  scenario = YAML::Node(YAML::NodeType::Map);
  scenario["name"] = type->name;
  scenario["description"] = "the linesim unit type " + type->name + " exported as an FMU";
  scenario["duration_s"] = "1";
  scenario["seed"] = "1";
  scenario["units"][instance] = resource_spec;
  if (!scene_text.empty()) scenario["scene"]["model"] = kSceneFile;  // beside this file

  ExportResult result;
  result.resource =
      "# The unit this FMU runs (linesim export-fmu), read by its binary at\n"
      "# fmi2Instantiate: a linesim scenario with this one unit.\n" +
      Emit(scenario);
  RefuseUnbuildableResource(scratch.path(), result.resource, scene_text, instance, type->name);
  result.model_identifier = type->name;
  result.guid = GuidOfResources(result.resource, scene_text);
  const DescriptionInfo info{type->name, result.model_identifier, result.guid,
                             "linesim unit type " + type->name + ": " + type->description};
  if (o.fmi_version != 0 && o.fmi_version != 2 && o.fmi_version != 3) {
    throw ExportError("FMI version " + std::to_string(o.fmi_version) + ": linesim writes 2 or 3");
  }
  result.fmi_version = o.fmi_version;
  if (result.fmi_version == 0) {
    result.fmi_version = 2;
    for (const auto& v : unit.variables().infos()) {
      if (v.type == cosim::VarType::kRealArray && v.size > 1) result.fmi_version = 3;
    }
  }
  if (result.fmi_version == 2) {
    const Layout layout = MakeLayout(unit.variables());
    result.variables = layout.variables.size();
    result.model_description = WriteModelDescription(unit, layout, info);
  } else {
    result.variables = unit.variables().size();
    result.model_description = WriteModelDescription3(unit, info);
  }

  // The FMU, written beside its final name and renamed into place.
  const fs::path out = fs::absolute(o.out);
  if (out.has_parent_path() && !fs::is_directory(out.parent_path())) {
    throw ExportError("cannot write " + o.out + ": no folder " + out.parent_path().string());
  }
  // Refused before anything is written: an FMU replaces a file, never a folder.
  {
    std::error_code status_ec;
    const fs::file_status st = fs::symlink_status(out, status_ec);
    if (fs::exists(st) && !fs::is_regular_file(st)) {
      throw ExportError("cannot write " + o.out + ": it exists and is not a file (a folder?)");
    }
  }
  const std::string partial = out.string() + ".partial";
  std::error_code ec;
  fs::remove(partial, ec);
  int error = 0;
  zip_t* zip = zip_open(partial.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  if (!zip) throw ExportError("cannot create " + partial);
  try {
    AddBuffer(zip, "modelDescription.xml", result.model_description);
    AddBuffer(zip, std::string("resources/") + kResourceFile, result.resource);
    if (!scene_text.empty()) AddBuffer(zip, std::string("resources/") + kSceneFile, scene_text);
    zip_source_t* so = zip_source_file(zip, runtime.c_str(), 0, -1);
    const std::string so_name =
        std::string(result.fmi_version == 2 ? "binaries/linux64/" : "binaries/x86_64-linux/") +
        result.model_identifier + ".so";
    if (!so || zip_file_add(zip, so_name.c_str(), so, ZIP_FL_OVERWRITE) < 0) {
      if (so) zip_source_free(so);
      throw ExportError("cannot add " + runtime + " to the FMU: " + zip_strerror(zip));
    }
  } catch (...) {
    zip_discard(zip);
    throw;
  }
  if (zip_close(zip) < 0) {
    const std::string why = zip_strerror(zip);
    zip_discard(zip);
    throw ExportError("cannot write " + o.out + ": " + why);
  }
  fs::rename(partial, out, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(partial, ignored);  // nothing half-written stays behind
    throw ExportError("cannot write " + o.out + ": " + ec.message());
  }
  return result;
}

}  // namespace linesim::fmu_export
