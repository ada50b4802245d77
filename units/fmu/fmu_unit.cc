#include "units/fmu/fmu_unit.h"

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <type_traits>

#include "units/fmu/fmi_api.h"
#include "units/fmu/fmu_archive.h"

namespace linesim::fmu {

namespace fs = std::filesystem;
using cosim::StepResult;
using cosim::TimeNs;
using cosim::UnitError;

// ---------------------------------------------------------------------------
// The platform binary and its functions.

class FmuBinary {
 public:
  FmuBinary(const std::string& so, const ModelDescription& md, const std::string& fmu_file)
      : file_(fmu_file), so_(so) {
    handle_ = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle_) {
      const char* why = dlerror();
      throw FmuError(fmu_file + ": cannot load the binary " + so + ": " + (why ? why : "?"));
    }
    const bool state = md.can_get_and_set_state;
    const bool serialize = state && md.can_serialize_state;
    if (md.fmi_major == 2) {
      Resolve(f2.GetVersion, "fmi2GetVersion");
      Resolve(f2.Instantiate, "fmi2Instantiate");
      Resolve(f2.FreeInstance, "fmi2FreeInstance");
      Resolve(f2.SetupExperiment, "fmi2SetupExperiment");
      Resolve(f2.EnterInitializationMode, "fmi2EnterInitializationMode");
      Resolve(f2.ExitInitializationMode, "fmi2ExitInitializationMode");
      Resolve(f2.Terminate, "fmi2Terminate");
      Resolve(f2.GetReal, "fmi2GetReal");
      Resolve(f2.GetInteger, "fmi2GetInteger");
      Resolve(f2.GetBoolean, "fmi2GetBoolean");
      Resolve(f2.GetString, "fmi2GetString");
      Resolve(f2.SetReal, "fmi2SetReal");
      Resolve(f2.SetInteger, "fmi2SetInteger");
      Resolve(f2.SetBoolean, "fmi2SetBoolean");
      Resolve(f2.SetString, "fmi2SetString");
      Resolve(f2.DoStep, "fmi2DoStep");
      Resolve(f2.GetRealStatus, "fmi2GetRealStatus", false);
      Resolve(f2.GetBooleanStatus, "fmi2GetBooleanStatus", false);
      Resolve(f2.GetFMUstate, "fmi2GetFMUstate", state);
      Resolve(f2.SetFMUstate, "fmi2SetFMUstate", state);
      Resolve(f2.FreeFMUstate, "fmi2FreeFMUstate", state);
      Resolve(f2.SerializedFMUstateSize, "fmi2SerializedFMUstateSize", serialize);
      Resolve(f2.SerializeFMUstate, "fmi2SerializeFMUstate", serialize);
      Resolve(f2.DeSerializeFMUstate, "fmi2DeSerializeFMUstate", serialize);
    } else {
      Resolve(f3.GetVersion, "fmi3GetVersion");
      Resolve(f3.InstantiateCoSimulation, "fmi3InstantiateCoSimulation");
      Resolve(f3.FreeInstance, "fmi3FreeInstance");
      Resolve(f3.EnterInitializationMode, "fmi3EnterInitializationMode");
      Resolve(f3.ExitInitializationMode, "fmi3ExitInitializationMode");
      Resolve(f3.Terminate, "fmi3Terminate");
      Resolve(f3.GetFloat64, "fmi3GetFloat64");
      Resolve(f3.GetInt32, "fmi3GetInt32");
      Resolve(f3.GetBoolean, "fmi3GetBoolean");
      Resolve(f3.GetString, "fmi3GetString");
      Resolve(f3.SetFloat64, "fmi3SetFloat64");
      Resolve(f3.SetInt32, "fmi3SetInt32");
      Resolve(f3.SetBoolean, "fmi3SetBoolean");
      Resolve(f3.SetString, "fmi3SetString");
      Resolve(f3.DoStep, "fmi3DoStep");
      Resolve(f3.GetFloat32, "fmi3GetFloat32", false);
      Resolve(f3.SetFloat32, "fmi3SetFloat32", false);
      Resolve(f3.GetInt8, "fmi3GetInt8", false);
      Resolve(f3.SetInt8, "fmi3SetInt8", false);
      Resolve(f3.GetUInt8, "fmi3GetUInt8", false);
      Resolve(f3.SetUInt8, "fmi3SetUInt8", false);
      Resolve(f3.GetInt16, "fmi3GetInt16", false);
      Resolve(f3.SetInt16, "fmi3SetInt16", false);
      Resolve(f3.GetUInt16, "fmi3GetUInt16", false);
      Resolve(f3.SetUInt16, "fmi3SetUInt16", false);
      Resolve(f3.GetUInt32, "fmi3GetUInt32", false);
      Resolve(f3.SetUInt32, "fmi3SetUInt32", false);
      Resolve(f3.GetInt64, "fmi3GetInt64", false);
      Resolve(f3.SetInt64, "fmi3SetInt64", false);
      Resolve(f3.GetUInt64, "fmi3GetUInt64", false);
      Resolve(f3.SetUInt64, "fmi3SetUInt64", false);
      Resolve(f3.GetFMUState, "fmi3GetFMUState", state);
      Resolve(f3.SetFMUState, "fmi3SetFMUState", state);
      Resolve(f3.FreeFMUState, "fmi3FreeFMUState", state);
      Resolve(f3.SerializedFMUStateSize, "fmi3SerializedFMUStateSize", serialize);
      Resolve(f3.SerializeFMUState, "fmi3SerializeFMUState", serialize);
      Resolve(f3.DeserializeFMUState, "fmi3DeserializeFMUState", serialize);
    }
    const char* version = md.fmi_major == 2 ? f2.GetVersion() : f3.GetVersion();
    const std::string v = version ? version : "";
    if (v.empty() || v[0] != static_cast<char>('0' + md.fmi_major)) {
      throw FmuError(fmu_file + ": the binary reports FMI version '" + v +
                     "', the model description " + md.fmi_version);
    }
  }
  ~FmuBinary() {
    if (handle_) dlclose(handle_);
  }
  /// Throws FmuError when the binary lacks fmi3Get<T> / fmi3Set<T> of a
  /// type the FMU has variables of.
  void RequireTypeFunctions(FmiType type) const {
    const auto need = [&](const void* get, const void* set, const char* name) {
      if (!get || !set) {
        throw FmuError(file_ + ": the binary " + fs::path(so_).filename().string() +
                       " does not export fmi3Get" + name + " / fmi3Set" + name +
                       ", and the FMU has " + name + " variables (missing symbol)");
      }
    };
    const auto p = [](auto f) { return reinterpret_cast<const void*>(f); };
    switch (type) {
      case FmiType::kFloat32:
        need(p(f3.GetFloat32), p(f3.SetFloat32), "Float32");
        break;
      case FmiType::kInt8:
        need(p(f3.GetInt8), p(f3.SetInt8), "Int8");
        break;
      case FmiType::kUInt8:
        need(p(f3.GetUInt8), p(f3.SetUInt8), "UInt8");
        break;
      case FmiType::kInt16:
        need(p(f3.GetInt16), p(f3.SetInt16), "Int16");
        break;
      case FmiType::kUInt16:
        need(p(f3.GetUInt16), p(f3.SetUInt16), "UInt16");
        break;
      case FmiType::kUInt32:
        need(p(f3.GetUInt32), p(f3.SetUInt32), "UInt32");
        break;
      case FmiType::kInt64:
        need(p(f3.GetInt64), p(f3.SetInt64), "Int64");
        break;
      case FmiType::kUInt64:
        need(p(f3.GetUInt64), p(f3.SetUInt64), "UInt64");
        break;
      default:
        break;
    }
  }
  FmuBinary(const FmuBinary&) = delete;
  FmuBinary& operator=(const FmuBinary&) = delete;

  struct Fmi2 {
    fmi2::GetVersionTYPE GetVersion = nullptr;
    fmi2::InstantiateTYPE Instantiate = nullptr;
    fmi2::FreeInstanceTYPE FreeInstance = nullptr;
    fmi2::SetupExperimentTYPE SetupExperiment = nullptr;
    fmi2::EnterInitializationModeTYPE EnterInitializationMode = nullptr;
    fmi2::ExitInitializationModeTYPE ExitInitializationMode = nullptr;
    fmi2::TerminateTYPE Terminate = nullptr;
    fmi2::GetRealTYPE GetReal = nullptr;
    fmi2::GetIntegerTYPE GetInteger = nullptr;
    fmi2::GetBooleanTYPE GetBoolean = nullptr;
    fmi2::GetStringTYPE GetString = nullptr;
    fmi2::SetRealTYPE SetReal = nullptr;
    fmi2::SetIntegerTYPE SetInteger = nullptr;
    fmi2::SetBooleanTYPE SetBoolean = nullptr;
    fmi2::SetStringTYPE SetString = nullptr;
    fmi2::DoStepTYPE DoStep = nullptr;
    fmi2::GetRealStatusTYPE GetRealStatus = nullptr;
    fmi2::GetBooleanStatusTYPE GetBooleanStatus = nullptr;
    fmi2::GetFMUstateTYPE GetFMUstate = nullptr;
    fmi2::SetFMUstateTYPE SetFMUstate = nullptr;
    fmi2::FreeFMUstateTYPE FreeFMUstate = nullptr;
    fmi2::SerializedFMUstateSizeTYPE SerializedFMUstateSize = nullptr;
    fmi2::SerializeFMUstateTYPE SerializeFMUstate = nullptr;
    fmi2::DeSerializeFMUstateTYPE DeSerializeFMUstate = nullptr;
  } f2;
  struct Fmi3 {
    fmi3::GetVersionTYPE GetVersion = nullptr;
    fmi3::InstantiateCoSimulationTYPE InstantiateCoSimulation = nullptr;
    fmi3::FreeInstanceTYPE FreeInstance = nullptr;
    fmi3::EnterInitializationModeTYPE EnterInitializationMode = nullptr;
    fmi3::ExitInitializationModeTYPE ExitInitializationMode = nullptr;
    fmi3::TerminateTYPE Terminate = nullptr;
    fmi3::GetFloat64TYPE GetFloat64 = nullptr;
    fmi3::GetInt32TYPE GetInt32 = nullptr;
    fmi3::GetBooleanTYPE GetBoolean = nullptr;
    fmi3::GetStringTYPE GetString = nullptr;
    fmi3::SetFloat64TYPE SetFloat64 = nullptr;
    fmi3::SetInt32TYPE SetInt32 = nullptr;
    fmi3::SetBooleanTYPE SetBoolean = nullptr;
    fmi3::SetStringTYPE SetString = nullptr;
    fmi3::DoStepTYPE DoStep = nullptr;
    // The other scalar types: resolved when exported, required when the
    // FMU has a variable of the type (RequireTypeFunctions).
    fmi3::GetTYPE<fmi3::Float32> GetFloat32 = nullptr;
    fmi3::SetTYPE<fmi3::Float32> SetFloat32 = nullptr;
    fmi3::GetTYPE<fmi3::Int8> GetInt8 = nullptr;
    fmi3::SetTYPE<fmi3::Int8> SetInt8 = nullptr;
    fmi3::GetTYPE<fmi3::UInt8> GetUInt8 = nullptr;
    fmi3::SetTYPE<fmi3::UInt8> SetUInt8 = nullptr;
    fmi3::GetTYPE<fmi3::Int16> GetInt16 = nullptr;
    fmi3::SetTYPE<fmi3::Int16> SetInt16 = nullptr;
    fmi3::GetTYPE<fmi3::UInt16> GetUInt16 = nullptr;
    fmi3::SetTYPE<fmi3::UInt16> SetUInt16 = nullptr;
    fmi3::GetTYPE<fmi3::UInt32> GetUInt32 = nullptr;
    fmi3::SetTYPE<fmi3::UInt32> SetUInt32 = nullptr;
    fmi3::GetTYPE<fmi3::Int64> GetInt64 = nullptr;
    fmi3::SetTYPE<fmi3::Int64> SetInt64 = nullptr;
    fmi3::GetTYPE<fmi3::UInt64> GetUInt64 = nullptr;
    fmi3::SetTYPE<fmi3::UInt64> SetUInt64 = nullptr;
    fmi3::GetFMUStateTYPE GetFMUState = nullptr;
    fmi3::SetFMUStateTYPE SetFMUState = nullptr;
    fmi3::FreeFMUStateTYPE FreeFMUState = nullptr;
    fmi3::SerializedFMUStateSizeTYPE SerializedFMUStateSize = nullptr;
    fmi3::SerializeFMUStateTYPE SerializeFMUState = nullptr;
    fmi3::DeserializeFMUStateTYPE DeserializeFMUState = nullptr;
  } f3;

 private:
  template <typename F>
  void Resolve(F& f, const char* symbol, bool required = true) {
    dlerror();
    void* p = dlsym(handle_, symbol);
    if (!p && required) {
      throw FmuError(file_ + ": the binary " + fs::path(so_).filename().string() +
                     " does not export " + symbol + " (missing symbol)");
    }
    f = reinterpret_cast<F>(p);
  }

  std::string file_;
  std::string so_;
  void* handle_ = nullptr;
};

// ---------------------------------------------------------------------------
// Callbacks.

namespace {

const char* StatusName(int major, int status) {
  static const char* k2[] = {"fmi2OK",    "fmi2Warning", "fmi2Discard",
                             "fmi2Error", "fmi2Fatal",   "fmi2Pending"};
  static const char* k3[] = {"fmi3OK", "fmi3Warning", "fmi3Discard", "fmi3Error", "fmi3Fatal"};
  if (major == 2 && status >= 0 && status <= 5) return k2[status];
  if (major == 3 && status >= 0 && status <= 4) return k3[status];
  return "an unknown status";
}

extern "C" {
static void Logger2(void* env, const char* /*instance*/, fmi2::Status status, const char* category,
                    const char* message, ...) {
  if (!env || !message) return;
  char text[1024];
  va_list args;
  va_start(args, message);
  std::vsnprintf(text, sizeof text, message, args);
  va_end(args);
  static_cast<FmuUnit*>(env)->Log(static_cast<int>(status), category, text);
}
static void* Allocate2(std::size_t count, std::size_t size) { return std::calloc(count, size); }
static void Free2(void* p) { std::free(p); }
static void Logger3(void* env, fmi3::Status status, const char* category, const char* message) {
  if (!env || !message) return;
  static_cast<FmuUnit*>(env)->Log(static_cast<int>(status), category, message);
}
}

// "motor.R" -> "motor_R": the FMI name as a linesim identifier.
std::string Identifier(const std::string& name) {
  std::string out;
  for (char c : name) {
    out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  }
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "v_" + out;
  return out;
}

std::atomic<std::int64_t> next_id{1};

// `relative`, a path inside the FMU built from its model description (the
// binary from the modelIdentifier), under the unpacked folder `root`,
// checked after resolving it: `..`, an absolute name or a link on the way
// could otherwise lead out of the folder (a modelIdentifier
// "../../../x/outside" loaded a library from beside it). Throws FmuError
// naming the FMU, the attribute and the path.
fs::path InsideFolder(const fs::path& root, const std::string& relative,
                      const std::string& fmu_file, const std::string& attribute) {
  const auto refuse = [&](const std::string& why) -> FmuError {
    return FmuError(fmu_file + ": " + attribute + " makes the path '" + relative + "', which " +
                    why +
                    ": refused (every path built from the model description must stay in "
                    "the FMU)");
  };
  std::error_code ec;
  const fs::path base = fs::canonical(root, ec);
  if (ec) throw FmuError(fmu_file + ": cannot resolve the unpacked folder: " + ec.message());
  // An absolute `relative` would replace `base` altogether in base / relative.
  if (fs::path(relative).has_root_path()) throw refuse("is absolute");
  const fs::path resolved = fs::weakly_canonical(base / relative, ec);
  if (ec) throw refuse("cannot be resolved (" + ec.message() + ")");
  // Inside means: base's components are a proper prefix of resolved's.
  const auto [b, r] = std::mismatch(base.begin(), base.end(), resolved.begin(), resolved.end());
  if (b != base.end() || r == resolved.end()) throw refuse("leads outside the unpacked FMU");
  return resolved;
}

}  // namespace

void FmuUnit::Log(int status, const char* category, const char* message) {
  ++message_count_;
  if (messages_.size() >= kMaxMessages) messages_.pop_front();
  messages_.push_back(std::string(StatusName(description_.fmi_major, status)) + " [" +
                      (category ? category : "") + "] " + message);
}

// ---------------------------------------------------------------------------
// Loading.

FmuUnit::FmuUnit(std::string name) : cosim::Unit(kTypeName, std::move(name)) {
  variables().Local("placeholder", "1", &placeholder_,
                    "no FMU loaded: the variables are the FMU's (parameters.path); "
                    "`linesim inspect FILE.fmu` lists them");
}

FmuUnit::FmuUnit(std::string name, const std::string& fmu_file)
    : cosim::Unit(kTypeName, std::move(name)), file_(fmu_file), id_(next_id++) {
  std::error_code ec;
  if (!fs::is_regular_file(fmu_file, ec)) {
    throw FmuError(fmu_file + ": no such FMU file");
  }
  folder_ = std::make_unique<TempFolder>();
  Unpack(fmu_file, folder_->path());
  const fs::path root(folder_->path());
  const fs::path md_file = root / "modelDescription.xml";
  if (!fs::is_regular_file(md_file, ec)) {
    throw FmuError(fmu_file + ": the archive has no modelDescription.xml (not an FMU)");
  }
  try {
    description_ = ParseModelDescription(md_file.string());
  } catch (const FmuError& e) {
    // Name the file inside the FMU, not the temporary folder.
    std::string what = e.what();
    const std::string prefix = md_file.string();
    if (what.rfind(prefix, 0) == 0)
      what = fmu_file + "/modelDescription.xml" + what.substr(prefix.size());
    throw FmuError(what);
  }
  if (fs::exists(root / "terminalsAndIcons" / "terminalsAndIcons.xml", ec)) {
    throw FmuError(fmu_file +
                   ": terminalsAndIcons/terminalsAndIcons.xml declares terminals: FMI 3.0 "
                   "terminals are not supported");
  }
  const char* platform = description_.fmi_major == 2 ? "linux64" : "x86_64-linux";
  const fs::path so = InsideFolder(
      root, std::string("binaries/") + platform + "/" + description_.model_identifier + ".so",
      fmu_file, "modelIdentifier '" + description_.model_identifier + "'");
  if (!fs::is_regular_file(so, ec)) {
    std::string found;
    for (const auto& e : fs::directory_iterator(root / "binaries", ec)) {
      found += (found.empty() ? "" : ", ") + e.path().filename().string();
    }
    throw FmuError(fmu_file + ": no binary for this platform: binaries/" + platform + "/" +
                   description_.model_identifier +
                   ".so is missing (binaries for: " + (found.empty() ? "none" : found) + ")");
  }
  binary_ = std::make_unique<FmuBinary>(so.string(), description_, fmu_file);
  DeclareVariables();
}

FmuUnit::~FmuUnit() { FreeInstance(); }

void FmuUnit::DeclareVariables() {
  const auto& vars = description_.variables;
  auto& table = variables();
  // Which group each variable joins; -1: left out; kDirections: a
  // structural parameter (read-only, no group).
  std::vector<int> direction(vars.size(), -1);
  std::size_t count[4] = {};  // scalar slots per type
  std::size_t array_count = 0;
  for (std::size_t i = 0; i < vars.size(); ++i) {
    const FmiVariable& v = vars[i];
    int d = -1;
    if (v.causality == "parameter") {
      d = v.variability == "tunable" ? kTunables : kParameters;
    } else if (v.causality == "structuralParameter") {
      d = kDirections;
    } else if (v.causality == "input") {
      d = kInputs;
    } else if (v.causality == "output") {
      d = kOutputs;
    } else if ((v.causality == "local" || v.causality == "calculatedParameter") &&
               v.type == FmiType::kFloat64) {
      d = kLocals;
    }
    direction[i] = d;
    mapping_.push_back({v.name, "", v.value_reference, d >= 0});
    if (d < 0) continue;
    if (!v.dimensions.empty()) {
      ++array_count;
    } else {
      ++count[StorageOf(v.type)];
      binary_->RequireTypeFunctions(v.type);
    }
  }
  for (const std::string& name : description_.left_out) mapping_.push_back({name, "", 0, false});
  conversion_ =
      std::make_unique<unsigned char[]>(8 * std::max<std::size_t>({count[0], count[1], 1}));
  integer_variable_.assign(count[1], 0);
  reals_ = std::make_unique<double[]>(count[0]);
  integers_ = std::make_unique<std::int64_t[]>(count[1]);
  booleans_ = std::make_unique<bool[]>(count[2]);
  strings_.resize(count[3]);
  arrays_.reserve(array_count);  // never grows after: the table keeps addresses
  int_buffer_.resize(std::max(count[1], count[2]));
  string_buffer_.resize(count[3]);

  std::set<std::string> used;
  std::map<std::size_t, std::string> input_names;  // variable index -> table name
  // Per identifier, the suffix to try next: names that all become one
  // identifier ("a.b", "a_b", ...) would otherwise search from _2 each time,
  // quadratic in their number. The names are the same as with that search
  // (the set of used names only grows).
  std::map<std::string, int> next_suffix;
  const auto unique_name = [&](const std::string& fmi_name) {
    std::string n = Identifier(fmi_name);
    if (used.count(n)) {
      int& k = next_suffix.try_emplace(n, 2).first->second;
      while (used.count(n + "_" + std::to_string(k))) ++k;
      n += "_" + std::to_string(k++);
    }
    used.insert(n);
    return n;
  };
  std::size_t next[4] = {};  // per storage
  for (int d = 0; d <= kDirections; ++d) {
    for (int t = 0; t <= kFmiTypeCount; ++t) {  // kFmiTypeCount: arrays of Float64
      const bool arrays = t == kFmiTypeCount;
      const FmiType type = arrays ? FmiType::kFloat64 : static_cast<FmiType>(t);
      const int storage = StorageOf(type);
      Group* g = nullptr;
      if (d < kDirections && !arrays) {
        Groups& gs = groups_[d];
        if (t < 4) {
          g = t == 0 ? &gs.real : t == 1 ? &gs.integer : t == 2 ? &gs.boolean : &gs.string;
        } else {
          gs.extras.push_back({type, {}});
          g = &gs.extras.back().group;
        }
        g->first = next[storage];
      }
      for (std::size_t i = 0; i < vars.size(); ++i) {
        const FmiVariable& v = vars[i];
        if (direction[i] != d) continue;
        const bool is_array = !v.dimensions.empty();
        if (arrays ? !is_array : (is_array || v.type != type)) continue;
        const std::string name = unique_name(v.name);
        mapping_[i].name = name;
        std::string text = v.description;
        text += (text.empty() ? "" : " ") + std::string("(FMI '") + v.name + "', vr " +
                std::to_string(v.value_reference);
        if (!v.fmi_unit.empty() && v.fmi_unit != v.unit) text += ", unit '" + v.fmi_unit + "'";
        if (v.causality == "calculatedParameter") text += ", calculated parameter";
        if (v.type != FmiType::kFloat64 && v.type != FmiType::kInt32 &&
            v.type != FmiType::kBoolean && v.type != FmiType::kString) {
          text += std::string(", ") + ToString(v.type);
        }
        if (!v.items.empty()) {
          text += ", enumeration '" + v.declared_type + "':";
          for (const auto& [value, item] : v.items)
            text += " " + std::to_string(value) + " " + item;
        }
        if (v.min) text += ", min " + cosim::FormatValue(*v.min);
        if (v.max) text += ", max " + cosim::FormatValue(*v.max);
        if (v.nominal) text += ", nominal " + cosim::FormatValue(*v.nominal);
        // The table shows 0 for it until the FMU gives a value.
        if (!v.has_start) text += ", no start value";
        if (v.dimensions.size() > 1) {
          text += ", ";
          for (std::size_t k = 0; k < v.dimensions.size(); ++k) {
            text += (k ? "x" : "") + std::to_string(v.dimensions[k]);
          }
          text += " row-major";
        }
        text += ")";
        // ModelStructure's direct dependencies hold in initialization mode
        // only: in step mode a co-simulation FMU's outputs are those doStep
        // computed, and no fmi*Get may follow an fmi*Set before the next
        // doStep (FMI 2.0.4 section 4.2.4, FMI 3.0.2 Step Mode). So the
        // outputs depend on no input at a communication point: the master
        // neither orders nor loops on them, and never asks for outputs
        // after setting inputs. Initialize() reads them after setting the
        // inputs, as initialization mode allows.
        const std::vector<std::string> deps;
        if (d == kOutputs && (!v.dependencies || !v.dependencies->empty())) {
          std::string on;
          if (v.dependencies) {
            for (auto index : *v.dependencies) {
              if (auto it = input_names.find(index); it != input_names.end()) {
                on += (on.empty() ? "" : " ") + it->second;
              }
            }
          }
          text.insert(text.size() - 1, std::string(", depends on ") +
                                           (v.dependencies ? on : "every input") +
                                           " in initialization mode");
        }
        const cosim::Variability variability = d == kDirections ? cosim::Variability::kConstant
                                               : d == kTunables ? cosim::Variability::kTunable
                                                                : cosim::Variability::kFixed;
        const bool parameter = d == kParameters || d == kTunables || d == kDirections;
        if (arrays) {
          arrays_.emplace_back(v.size, 0.0);
          std::vector<double>* slot = &arrays_.back();
          if (v.has_start) *slot = v.start_reals;
          if (d < kDirections) groups_[d].arrays.push_back({v.value_reference, arrays_.size() - 1});
          if (parameter) {
            table.Parameter(name, v.unit, slot, text, variability);
          } else if (d == kInputs) {
            table.Input(name, v.unit, slot, text);
          } else if (d == kOutputs) {
            table.Output(name, v.unit, slot, text, deps);
          } else {
            table.Local(name, v.unit, slot, text);
          }
        } else {
          const std::size_t k = next[storage]++;
          if (g) g->vrs.push_back(v.value_reference);
          // An Integer, Boolean or String (no unit of measure) at `slot`,
          // as a parameter, an input or an output.
          const auto DeclareScalar = [&](auto* slot, const auto& start) {
            *slot = start;
            if (parameter) {
              table.Parameter(name, slot, text, variability);
            } else if (d == kInputs) {
              table.Input(name, slot, text);
            } else {
              table.Output(name, slot, text, deps);
            }
          };
          switch (storage) {
            case 0: {
              double* slot = &reals_[k];
              *slot = v.has_start ? v.start_reals[0] : 0.0;
              if (parameter) {
                table.Parameter(name, v.unit, slot, text, variability);
              } else if (d == kInputs) {
                table.Input(name, v.unit, slot, text);
              } else if (d == kOutputs) {
                table.Output(name, v.unit, slot, text, deps);
              } else {
                table.Local(name, v.unit, slot, text);
              }
              break;
            }
            case 1:
              integer_variable_[k] = i;
              DeclareScalar(&integers_[k], v.start_integer);
              break;
            case 2:
              DeclareScalar(&booleans_[k], v.start_boolean);
              break;
            default:
              DeclareScalar(&strings_[k], v.start_string);
              break;
          }
        }
        if (d == kInputs) {
          input_names[i] = name;
        }
      }
      if (g && t >= 4 && g->vrs.empty()) groups_[d].extras.pop_back();
    }
  }
  // Tunable parameters: what was last given to the FMU.
  const Groups& tun = groups_[kTunables];
  has_tunables_ = !tun.real.vrs.empty() || !tun.integer.vrs.empty() || !tun.boolean.vrs.empty() ||
                  !tun.string.vrs.empty() || !tun.arrays.empty() || !tun.extras.empty();
}

std::vector<cosim::ParameterProblem> FmuUnit::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  if (!binary_) {
    problems.push_back(
        {"path", std::nullopt, "must be set: the FMU file (.fmu), relative to the scenario file"});
  }
  return problems;
}

// ---------------------------------------------------------------------------
// Calls.

std::string FmuUnit::RecentMessages(std::size_t since) const {
  // The messages logged since message number `since`, as far as kept.
  std::string text;
  const std::size_t recent = std::min(message_count_ - since, messages_.size());
  for (std::size_t i = messages_.size() - recent; i < messages_.size(); ++i) {
    text += "; FMU log: " + messages_[i];
  }
  return text;
}

std::string FmuUnit::Describe(const char* call, int status) const {
  return std::string(call) + " returned " + StatusName(description_.fmi_major, status);
}

void FmuUnit::Check(int status, const char* call, const char* phase) {
  if (status == 0 || status == 1) return;  // OK, Warning (kept in the log)
  // Fatal: no further call. Error: no call but freeing the instance or
  // restoring a state (FMI 2.0.4 section 2.1.3, FMI 3.0 section 2.2.3): in
  // particular no Terminate, whatever phase failed.
  if (status == 4) mode_ = Mode::kBroken;
  if (status == 3 && mode_ != Mode::kBroken) mode_ = Mode::kError;
  throw UnitError(Where() + ": " + phase + ": " + Describe(call, status) +
                  RecentMessages(call_messages_));
}

void FmuUnit::SetGroups(const Groups& g, const char* phase) {
  void* c = instance_;
  if (description_.fmi_major == 2) {
    const auto& f = binary_->f2;
    if (const std::size_t n = g.real.vrs.size()) {
      Check(f.SetReal(c, g.real.vrs.data(), n, &reals_[g.real.first]), "fmi2SetReal", phase);
    }
    if (const std::size_t n = g.integer.vrs.size()) {
      for (std::size_t i = 0; i < n; ++i) {
        const std::int64_t x = integers_[g.integer.first + i];
        CheckInteger(g.integer.first + i, x, phase);
        int_buffer_[i] = static_cast<int>(x);
      }
      Check(f.SetInteger(c, g.integer.vrs.data(), n, int_buffer_.data()), "fmi2SetInteger", phase);
    }
    if (const std::size_t n = g.boolean.vrs.size()) {
      for (std::size_t i = 0; i < n; ++i) int_buffer_[i] = booleans_[g.boolean.first + i] ? 1 : 0;
      Check(f.SetBoolean(c, g.boolean.vrs.data(), n, int_buffer_.data()), "fmi2SetBoolean", phase);
    }
    if (const std::size_t n = g.string.vrs.size()) {
      for (std::size_t i = 0; i < n; ++i) string_buffer_[i] = strings_[g.string.first + i].c_str();
      Check(f.SetString(c, g.string.vrs.data(), n, string_buffer_.data()), "fmi2SetString", phase);
    }
    return;
  }
  const auto& f = binary_->f3;
  if (const std::size_t n = g.real.vrs.size()) {
    Check(f.SetFloat64(c, g.real.vrs.data(), n, &reals_[g.real.first], n), "fmi3SetFloat64", phase);
  }
  for (const ArraySlot& a : g.arrays) {
    const auto& values = arrays_[a.index];
    Check(f.SetFloat64(c, &a.vr, 1, values.data(), values.size()), "fmi3SetFloat64", phase);
  }
  if (const std::size_t n = g.integer.vrs.size()) {
    for (std::size_t i = 0; i < n; ++i) {
      const std::int64_t x = integers_[g.integer.first + i];
      CheckInteger(g.integer.first + i, x, phase);
      int_buffer_[i] = static_cast<int>(x);
    }
    static_assert(sizeof(int) == sizeof(fmi3::Int32));
    Check(f.SetInt32(c, g.integer.vrs.data(), n,
                     reinterpret_cast<const fmi3::Int32*>(int_buffer_.data()), n),
          "fmi3SetInt32", phase);
  }
  if (const std::size_t n = g.boolean.vrs.size()) {
    Check(f.SetBoolean(c, g.boolean.vrs.data(), n, &booleans_[g.boolean.first], n),
          "fmi3SetBoolean", phase);
  }
  if (const std::size_t n = g.string.vrs.size()) {
    for (std::size_t i = 0; i < n; ++i) string_buffer_[i] = strings_[g.string.first + i].c_str();
    Check(f.SetString(c, g.string.vrs.data(), n, string_buffer_.data(), n), "fmi3SetString", phase);
  }
  for (const TypedGroup& x : g.extras) SetExtra(x, phase);
}

void FmuUnit::CheckInteger(std::size_t slot, std::int64_t x, const char* phase) const {
  const FmiVariable& v = description_.variables[integer_variable_[slot]];
  const auto [lo, hi] = IntegerRange(v.type);
  if (x < lo || x > hi) {
    throw UnitError(Where() + ": " + phase + ": " + ToString(v.type) + " value " +
                        std::to_string(x) + " of '" + v.name + "' is outside the " +
                        ToString(v.type) + " range [" + std::to_string(lo) + ", " +
                        std::to_string(hi) + "]",
                    v.name);
  }
  if (v.items.empty()) return;
  const auto it =
      std::lower_bound(v.items.begin(), v.items.end(), x,
                       [](const auto& item, std::int64_t value) { return item.first < value; });
  if (it == v.items.end() || it->first != x) {
    std::string items;
    for (const auto& [value, name] : v.items) {
      items += (items.empty() ? "" : ", ") + std::to_string(value) + " (" + name + ")";
    }
    throw UnitError(Where() + ": " + phase + ": value " + std::to_string(x) + " of '" + v.name +
                        "' is no item of enumeration '" + v.declared_type + "': " + items,
                    v.name);
  }
}

// The other FMI 3.0 types, converted through conversion_ (range-checked
// before the conversion, so that nothing wraps).
void FmuUnit::SetExtra(const TypedGroup& x, const char* phase) {
  const auto& f = binary_->f3;
  const Group& g = x.group;
  const std::size_t n = g.vrs.size();
  const auto set = [&](auto function, auto zero, const char* call) {
    using T = decltype(zero);
    T* buffer = reinterpret_cast<T*>(conversion_.get());
    for (std::size_t i = 0; i < n; ++i) {
      if constexpr (std::is_floating_point_v<T>) {
        const double v = reals_[g.first + i];
        if (std::isfinite(v) && std::fabs(v) > FLT_MAX) {
          throw UnitError(Where() + ": " + phase + ": Float32 value " + cosim::FormatValue(v) +
                          " (vr " + std::to_string(g.vrs[i]) + ") is outside the Float32 range");
        }
        buffer[i] = static_cast<T>(v);
      } else {
        const std::int64_t v = integers_[g.first + i];
        CheckInteger(g.first + i, v, phase);
        buffer[i] = static_cast<T>(v);
      }
    }
    Check(function(instance_, g.vrs.data(), n, buffer, n), call, phase);
  };
  switch (x.type) {
    case FmiType::kFloat32:
      set(f.SetFloat32, fmi3::Float32{}, "fmi3SetFloat32");
      break;
    case FmiType::kInt8:
      set(f.SetInt8, fmi3::Int8{}, "fmi3SetInt8");
      break;
    case FmiType::kUInt8:
      set(f.SetUInt8, fmi3::UInt8{}, "fmi3SetUInt8");
      break;
    case FmiType::kInt16:
      set(f.SetInt16, fmi3::Int16{}, "fmi3SetInt16");
      break;
    case FmiType::kUInt16:
      set(f.SetUInt16, fmi3::UInt16{}, "fmi3SetUInt16");
      break;
    case FmiType::kUInt32:
      set(f.SetUInt32, fmi3::UInt32{}, "fmi3SetUInt32");
      break;
    case FmiType::kInt64:
      set(f.SetInt64, fmi3::Int64{}, "fmi3SetInt64");
      break;
    case FmiType::kUInt64:
      set(f.SetUInt64, fmi3::UInt64{}, "fmi3SetUInt64");
      break;
    default:
      break;
  }
}

void FmuUnit::GetExtra(const TypedGroup& x, const char* phase) {
  const auto& f = binary_->f3;
  const Group& g = x.group;
  const std::size_t n = g.vrs.size();
  const auto get = [&](auto function, auto zero, const char* call) {
    using T = decltype(zero);
    T* buffer = reinterpret_cast<T*>(conversion_.get());
    Check(function(instance_, g.vrs.data(), n, buffer, n), call, phase);
    for (std::size_t i = 0; i < n; ++i) {
      if constexpr (std::is_floating_point_v<T>) {
        reals_[g.first + i] = buffer[i];
      } else {
        if constexpr (std::is_same_v<T, fmi3::UInt64>) {
          if (buffer[i] > static_cast<fmi3::UInt64>(INT64_MAX)) {
            throw UnitError(Where() + ": " + phase + ": UInt64 value " + std::to_string(buffer[i]) +
                            " (vr " + std::to_string(g.vrs[i]) +
                            ") is above linesim's Integer range (at most 2^63 - 1)");
          }
        }
        integers_[g.first + i] = static_cast<std::int64_t>(buffer[i]);
      }
    }
  };
  switch (x.type) {
    case FmiType::kFloat32:
      get(f.GetFloat32, fmi3::Float32{}, "fmi3GetFloat32");
      break;
    case FmiType::kInt8:
      get(f.GetInt8, fmi3::Int8{}, "fmi3GetInt8");
      break;
    case FmiType::kUInt8:
      get(f.GetUInt8, fmi3::UInt8{}, "fmi3GetUInt8");
      break;
    case FmiType::kInt16:
      get(f.GetInt16, fmi3::Int16{}, "fmi3GetInt16");
      break;
    case FmiType::kUInt16:
      get(f.GetUInt16, fmi3::UInt16{}, "fmi3GetUInt16");
      break;
    case FmiType::kUInt32:
      get(f.GetUInt32, fmi3::UInt32{}, "fmi3GetUInt32");
      break;
    case FmiType::kInt64:
      get(f.GetInt64, fmi3::Int64{}, "fmi3GetInt64");
      break;
    case FmiType::kUInt64:
      get(f.GetUInt64, fmi3::UInt64{}, "fmi3GetUInt64");
      break;
    default:
      break;
  }
}

void FmuUnit::GetGroups(const Groups& g, const char* phase) {
  void* c = instance_;
  if (description_.fmi_major == 2) {
    const auto& f = binary_->f2;
    if (const std::size_t n = g.real.vrs.size()) {
      Check(f.GetReal(c, g.real.vrs.data(), n, &reals_[g.real.first]), "fmi2GetReal", phase);
    }
    if (const std::size_t n = g.integer.vrs.size()) {
      Check(f.GetInteger(c, g.integer.vrs.data(), n, int_buffer_.data()), "fmi2GetInteger", phase);
      for (std::size_t i = 0; i < n; ++i) integers_[g.integer.first + i] = int_buffer_[i];
    }
    if (const std::size_t n = g.boolean.vrs.size()) {
      Check(f.GetBoolean(c, g.boolean.vrs.data(), n, int_buffer_.data()), "fmi2GetBoolean", phase);
      for (std::size_t i = 0; i < n; ++i) booleans_[g.boolean.first + i] = int_buffer_[i] != 0;
    }
    if (const std::size_t n = g.string.vrs.size()) {
      Check(f.GetString(c, g.string.vrs.data(), n, string_buffer_.data()), "fmi2GetString", phase);
      for (std::size_t i = 0; i < n; ++i) {
        strings_[g.string.first + i] = string_buffer_[i] ? string_buffer_[i] : "";
      }
    }
    return;
  }
  const auto& f = binary_->f3;
  if (const std::size_t n = g.real.vrs.size()) {
    Check(f.GetFloat64(c, g.real.vrs.data(), n, &reals_[g.real.first], n), "fmi3GetFloat64", phase);
  }
  for (const ArraySlot& a : g.arrays) {
    auto& values = arrays_[a.index];
    Check(f.GetFloat64(c, &a.vr, 1, values.data(), values.size()), "fmi3GetFloat64", phase);
  }
  if (const std::size_t n = g.integer.vrs.size()) {
    Check(f.GetInt32(c, g.integer.vrs.data(), n, reinterpret_cast<fmi3::Int32*>(int_buffer_.data()),
                     n),
          "fmi3GetInt32", phase);
    for (std::size_t i = 0; i < n; ++i) integers_[g.integer.first + i] = int_buffer_[i];
  }
  if (const std::size_t n = g.boolean.vrs.size()) {
    Check(f.GetBoolean(c, g.boolean.vrs.data(), n, &booleans_[g.boolean.first], n),
          "fmi3GetBoolean", phase);
  }
  if (const std::size_t n = g.string.vrs.size()) {
    Check(f.GetString(c, g.string.vrs.data(), n, string_buffer_.data(), n), "fmi3GetString", phase);
    for (std::size_t i = 0; i < n; ++i) {
      strings_[g.string.first + i] = string_buffer_[i] ? string_buffer_[i] : "";
    }
  }
  for (const TypedGroup& x : g.extras) GetExtra(x, phase);
}

// The tunable parameters, when one changed since they were last given.
void FmuUnit::SetTunables() {
  const Groups& g = groups_[kTunables];
  bool changed = false;
  for (std::size_t i = 0; i < g.real.vrs.size() && !changed; ++i) {
    changed = std::memcmp(&reals_[g.real.first + i], &sent_reals_[i], sizeof(double)) != 0;
  }
  for (std::size_t i = 0; i < g.integer.vrs.size() && !changed; ++i) {
    changed = integers_[g.integer.first + i] != sent_integers_[i];
  }
  for (std::size_t i = 0; i < g.boolean.vrs.size() && !changed; ++i) {
    changed = booleans_[g.boolean.first + i] != (sent_booleans_[i] != 0);
  }
  for (std::size_t i = 0; i < g.string.vrs.size() && !changed; ++i) {
    changed = strings_[g.string.first + i] != sent_strings_[i];
  }
  {
    std::size_t r = 0, k = 0;
    for (const TypedGroup& x : g.extras) {
      for (std::size_t i = 0; i < x.group.vrs.size() && !changed; ++i) {
        const std::size_t slot = x.group.first + i;
        changed = StorageOf(x.type) == 0
                      ? std::memcmp(&reals_[slot], &sent_extra_reals_[r++], sizeof(double)) != 0
                      : integers_[slot] != sent_extra_integers_[k++];
      }
    }
  }
  std::size_t offset = g.real.vrs.size();
  for (const ArraySlot& a : g.arrays) {
    const auto& v = arrays_[a.index];
    if (!changed) {
      changed = std::memcmp(v.data(), &sent_reals_[offset], v.size() * sizeof(double)) != 0;
    }
    offset += v.size();
  }
  if (!changed) return;
  SetGroups(g, "setting tunable parameters");
  RememberTunables();
}

void FmuUnit::RememberTunables() {
  const Groups& g = groups_[kTunables];
  sent_reals_.assign(&reals_[g.real.first], &reals_[g.real.first] + g.real.vrs.size());
  for (const ArraySlot& a : g.arrays) {
    sent_reals_.insert(sent_reals_.end(), arrays_[a.index].begin(), arrays_[a.index].end());
  }
  sent_integers_.assign(&integers_[g.integer.first],
                        &integers_[g.integer.first] + g.integer.vrs.size());
  sent_booleans_.clear();
  for (std::size_t i = 0; i < g.boolean.vrs.size(); ++i) {
    sent_booleans_.push_back(booleans_[g.boolean.first + i] ? 1 : 0);
  }
  sent_extra_reals_.clear();
  sent_extra_integers_.clear();
  for (const TypedGroup& x : g.extras) {
    for (std::size_t i = 0; i < x.group.vrs.size(); ++i) {
      const std::size_t slot = x.group.first + i;
      if (StorageOf(x.type) == 0) {
        sent_extra_reals_.push_back(reals_[slot]);
      } else {
        sent_extra_integers_.push_back(integers_[slot]);
      }
    }
  }
  sent_strings_.assign(
      strings_.begin() + static_cast<std::ptrdiff_t>(g.string.first),
      strings_.begin() + static_cast<std::ptrdiff_t>(g.string.first + g.string.vrs.size()));
}

// ---------------------------------------------------------------------------
// Lifecycle.

void FmuUnit::FreeInstance() {
  if (!instance_ || !binary_) return;
  if (mode_ == Mode::kBroken) {
    // After a fatal status the standard allows no further call.
    instance_ = nullptr;
    kept_states_.clear();
    return;
  }
  for (void*& s : kept_states_) {
    if (!s) continue;
    if (description_.fmi_major == 2) {
      binary_->f2.FreeFMUstate(instance_, &s);
    } else {
      binary_->f3.FreeFMUState(instance_, &s);
    }
  }
  kept_states_.clear();
  if (description_.fmi_major == 2) {
    binary_->f2.FreeInstance(instance_);
  } else {
    binary_->f3.FreeInstance(instance_);
  }
  instance_ = nullptr;
  mode_ = Mode::kNone;
}

void FmuUnit::Setup(TimeNs start, TimeNs stop) {
  if (!binary_) throw UnitError(Where() + ": no FMU: parameters.path must name one");
  FreeInstance();
  start_ = start;
  stop_ = stop;
  first_dt_ = 0;
  call_messages_ = message_count_;
  const std::string resources = (fs::path(folder_->path()) / "resources").string();
  if (description_.fmi_major == 2) {
    // The FMU keeps a pointer to the callbacks: they live in the unit, with
    // the unit as the environment the logger gets back.
    callbacks2_ = {Logger2, Allocate2, Free2, nullptr, this};
    const std::string uri = "file://" + resources;
    instance_ = binary_->f2.Instantiate(name().c_str(), fmi2::kCoSimulation,
                                        description_.token.c_str(), uri.c_str(), &callbacks2_,
                                        fmi2::kFalse, /*loggingOn=*/fmi2::kFalse);
  } else {
    const std::string path = resources + "/";
    instance_ = binary_->f3.InstantiateCoSimulation(
        name().c_str(), description_.token.c_str(), path.c_str(), false, /*loggingOn=*/false,
        /*eventModeUsed=*/false, /*earlyReturnAllowed=*/true, nullptr, 0, this, Logger3, nullptr);
  }
  if (!instance_) {
    throw UnitError(Where() + ": setup: the FMU refused to instantiate" +
                    RecentMessages(call_messages_));
  }
  mode_ = Mode::kInstantiated;
  if (description_.fmi_major == 2) {
    Check(binary_->f2.SetupExperiment(instance_, fmi2::kFalse, 0.0, cosim::NsToSeconds(start),
                                      stop > start ? fmi2::kTrue : fmi2::kFalse,
                                      cosim::NsToSeconds(stop)),
          "fmi2SetupExperiment", "setup");
  }
}

void FmuUnit::Initialize() {
  if (!binary_) throw UnitError(Where() + ": no FMU: parameters.path must name one");
  ThrowIfBadParameters();
  if (mode_ == Mode::kNone || mode_ == Mode::kTerminated) Setup(start_, stop_);
  call_messages_ = message_count_;
  if (mode_ == Mode::kInstantiated) {
    // Start values of parameters and inputs go in before initialization.
    SetGroups(groups_[kParameters], "initialize");
    SetGroups(groups_[kTunables], "initialize");
    SetGroups(groups_[kInputs], "initialize");
    RememberTunables();
    if (description_.fmi_major == 2) {
      Check(binary_->f2.EnterInitializationMode(instance_), "fmi2EnterInitializationMode",
            "initialize");
    } else {
      Check(binary_->f3.EnterInitializationMode(instance_, false, 0.0, cosim::NsToSeconds(start_),
                                                stop_ > start_, cosim::NsToSeconds(stop_)),
            "fmi3EnterInitializationMode", "initialize");
    }
    mode_ = Mode::kInitialization;
  } else if (mode_ != Mode::kInitialization) {
    throw UnitError(Where() + ": initialize: the FMU has already left initialization mode");
  }
  SetGroups(groups_[kInputs], "initialize");
  GetGroups(groups_[kOutputs], "initialize");
  GetGroups(groups_[kLocals], "initialize");
}

void FmuUnit::UpdateOutputs() {
  // Only in initialization mode may outputs be read after inputs were set
  // (see DeclareVariables); in step mode they are doStep's, as they are.
  if (!instance_ || mode_ != Mode::kInitialization) return;
  call_messages_ = message_count_;
  SetGroups(groups_[kInputs], "updating outputs");
  GetGroups(groups_[kOutputs], "updating outputs");
}

StepResult FmuUnit::DoStep(TimeNs t, TimeNs dt) {
  ClearError();
  if (mode_ == Mode::kError) {
    return Fail(
        Where() + ": the FMU returned an error before t = " + cosim::FormatSeconds(t) +
        " s: it cannot be stepped again (FMI: only freeing or restoring a state is allowed)");
  }
  if (mode_ != Mode::kInitialization && mode_ != Mode::kStep) {
    return Fail(Where() + ": the FMU is not initialized (or was terminated) at t = " +
                cosim::FormatSeconds(t) + " s");
  }
  call_messages_ = message_count_;
  if (!InputsFinite(t)) return StepResult::kError;
  // Step sizes the FMU cannot take, named before it is asked. A step that
  // is no multiple of fixedInternalStepSize is not among them: that
  // attribute is information (FMI 3.0, section 4.2.1), and an FMU that
  // cannot take such a step refuses it itself (its status and log are
  // reported).
  if (first_dt_ == 0) first_dt_ = dt;
  if (dt != first_dt_ && !description_.can_handle_variable_step) {
    return Fail(Where() + ": step size refused at t = " + cosim::FormatSeconds(t) + " s: the FMU " +
                "cannot handle a variable communication step size "
                "(canHandleVariableCommunicationStepSize is false); it was stepped with " +
                cosim::FormatSeconds(first_dt_) + " s, now " + cosim::FormatSeconds(dt) + " s");
  }
  const double target = cosim::NsToSeconds(t + dt);
  double tc = cosim::NsToSeconds(t);
  double h = cosim::NsToSeconds(dt);
  const bool v2 = description_.fmi_major == 2;
  const char* call = v2 ? "fmi2DoStep" : "fmi3DoStep";
  try {
    if (mode_ == Mode::kInitialization) {
      if (v2) {
        Check(binary_->f2.ExitInitializationMode(instance_), "fmi2ExitInitializationMode",
              "leaving initialization");
      } else {
        Check(binary_->f3.ExitInitializationMode(instance_), "fmi3ExitInitializationMode",
              "leaving initialization");
      }
      mode_ = Mode::kStep;
    }
    if (has_tunables_) SetTunables();
    SetGroups(groups_[kInputs], "step");
    int status = 0;
    double last_time = target;
    bool terminate = false;
    if (v2) {
      status = binary_->f2.DoStep(instance_, tc, h, fmi2::kTrue);
      if (status == fmi2::kDiscard) {
        if (binary_->f2.GetRealStatus) {
          double t_ok = 0;
          if (binary_->f2.GetRealStatus(instance_, fmi2::kLastSuccessfulTime, &t_ok) <= 1) {
            last_time = t_ok;
          }
        }
        // fmi2Discard with fmi2Terminated: the FMU ends the simulation
        // (FMI 2.0.4, section 4.2.3: the master calls fmi2Terminate), not
        // a step to retry smaller.
        fmi2::Boolean ended = fmi2::kFalse;
        terminate = binary_->f2.GetBooleanStatus &&
                    binary_->f2.GetBooleanStatus(instance_, fmi2::kTerminated, &ended) <= 1 &&
                    ended == fmi2::kTrue;
      }
    } else {
      // Early return (FMI 3.0, section 4.2.4, fmi3DoStep; the FMU is
      // instantiated with earlyReturnAllowed and without event mode): the
      // FMU stopped inside the step at lastSuccessfulTime, at an event it
      // handled itself (a bounce, a staircase's step), and is valid there.
      // The unit continues it from that time to the communication point
      // with the inputs held, as for the whole step; the other units and
      // the master see a step from t to t + dt as always, so the
      // communication points stay start + k h. An event at the end of the
      // step (lastSuccessfulTime = t + dt) is a step that succeeded.
      for (std::size_t returns = 0;; ++returns) {
        bool event_needed = false;
        bool early = false;
        last_time = tc + h;
        status = binary_->f3.DoStep(instance_, tc, h, true, &event_needed, &terminate, &early,
                                    &last_time);
        if (status > fmi3::kWarning || terminate || !early || !(last_time < target)) break;
        if (!(last_time > tc)) {
          return Fail(Where() + ": fmi3DoStep returned early at lastSuccessfulTime " +
                      cosim::FormatValue(last_time) + " s, not after the step's start " +
                      cosim::FormatValue(tc) + " s (no progress)" + RecentMessages(call_messages_));
        }
        if (returns >= kMaxEarlyReturns) {
          return Fail(Where() + ": fmi3DoStep returned early " + std::to_string(returns + 1) +
                      " times in the step from t = " + cosim::FormatSeconds(t) + " s to " +
                      cosim::FormatSeconds(t + dt) + " s (at most " +
                      std::to_string(kMaxEarlyReturns) + ": an event that does not end?)" +
                      RecentMessages(call_messages_));
        }
        ++early_returns_;
        tc = last_time;
        h = target - last_time;
      }
    }
    if (terminate && status <= 2) {
      // The FMU asks to end the simulation, its values valid at the time it
      // reached: they are read, and the run ends normally after this step.
      GetGroups(groups_[kOutputs], "step");
      GetGroups(groups_[kLocals], "step");
      RequestStop(std::string(call) + " returned " + StatusName(description_.fmi_major, status) +
                  (v2 ? " with fmi2Terminated = true" : " with terminateSimulation = true") +
                  " in the step from t = " + cosim::FormatSeconds(t) + " s (last successful time " +
                  cosim::FormatValue(last_time) + " s): the FMU asks to end the simulation" +
                  RecentMessages(call_messages_));
      return StepResult::kOk;
    }
    if (status == 2) {
      // Discard: the master decides (a fixed-step master stops, naming
      // unit and time). No unit name in front: the master's message names
      // it, around this.
      Fail(Describe(call, status) + " for the step from t = " + cosim::FormatSeconds(t) + " s to " +
           cosim::FormatSeconds(t + dt) + " s (last successful time " +
           cosim::FormatValue(last_time) + " s)" + RecentMessages(call_messages_));
      return StepResult::kDiscard;
    }
    if (status == 5) {
      return Fail(Where() + ": fmi2DoStep returned fmi2Pending at t = " + cosim::FormatSeconds(t) +
                  " s: asynchronous steps are not supported");
    }
    if (status >= 3) {
      mode_ = status == 4 ? Mode::kBroken : Mode::kError;
      std::string text = Where() + ": " + Describe(call, status) + " for the step of " +
                         cosim::FormatSeconds(dt) + " s at t = " + cosim::FormatSeconds(t) + " s";
      if (t == start_) text += " (its first step: does the FMU refuse this step size?)";
      return Fail(text + RecentMessages(call_messages_));
    }
    GetGroups(groups_[kOutputs], "step");
    GetGroups(groups_[kLocals], "step");
  } catch (const UnitError& e) {
    return Fail(e.what());
  }
  return StepResult::kOk;
}

void FmuUnit::Terminate() {
  if (!instance_ || mode_ == Mode::kBroken || mode_ == Mode::kTerminated) return;
  if (mode_ != Mode::kInitialization && mode_ != Mode::kStep) return;
  call_messages_ = message_count_;
  const int status = description_.fmi_major == 2
                         ? static_cast<int>(binary_->f2.Terminate(instance_))
                         : static_cast<int>(binary_->f3.Terminate(instance_));
  mode_ = Mode::kTerminated;
  Check(status, description_.fmi_major == 2 ? "fmi2Terminate" : "fmi3Terminate", "terminate");
}

// ---------------------------------------------------------------------------
// State.

void FmuUnit::SaveInternal(cosim::UnitState& state) const {
  // integers: mode, first step, id of this unit, kept-state index (-1:
  // serialized into strings[0], -2: no FMU instance).
  state.integers = {static_cast<std::int64_t>(mode_), first_dt_, id_, -2};
  if (!binary_ || !instance_ || mode_ == Mode::kNone) return;
  if (mode_ == Mode::kBroken || mode_ == Mode::kError) {
    throw UnitError(Where() + ": cannot save the state of an FMU after " +
                    (mode_ == Mode::kBroken ? "a fatal error" : "an error"));
  }
  if (!description_.can_get_and_set_state) {
    throw UnitError(Where() +
                    ": cannot save the state: the FMU does not offer it "
                    "(canGetAndSetFMUstate is not true in its modelDescription.xml)");
  }
  const bool v2 = description_.fmi_major == 2;
  void* fmu_state = nullptr;
  const int status = v2 ? static_cast<int>(binary_->f2.GetFMUstate(instance_, &fmu_state))
                        : static_cast<int>(binary_->f3.GetFMUState(instance_, &fmu_state));
  if (status > 1 || !fmu_state) {
    throw UnitError(Where() + ": cannot save the state: " +
                    Describe(v2 ? "fmi2GetFMUstate" : "fmi3GetFMUState", status));
  }
  if (description_.can_serialize_state) {
    std::size_t size = 0;
    int s = v2 ? static_cast<int>(binary_->f2.SerializedFMUstateSize(instance_, fmu_state, &size))
               : binary_->f3.SerializedFMUStateSize(instance_, fmu_state, &size);
    std::string bytes(size, '\0');
    if (s <= 1) {
      s = v2 ? static_cast<int>(
                   binary_->f2.SerializeFMUstate(instance_, fmu_state, bytes.data(), size))
             : static_cast<int>(binary_->f3.SerializeFMUState(
                   instance_, fmu_state, reinterpret_cast<fmi3::Byte*>(bytes.data()), size));
    }
    if (v2) {
      binary_->f2.FreeFMUstate(instance_, &fmu_state);
    } else {
      binary_->f3.FreeFMUState(instance_, &fmu_state);
    }
    if (s > 1) {
      throw UnitError(Where() + ": cannot serialize the FMU state: " +
                      Describe(v2 ? "fmi2SerializeFMUstate" : "fmi3SerializeFMUState", s));
    }
    state.integers[3] = -1;
    state.strings = {std::move(bytes)};
    return;
  }
  // Kept by the FMU, freed with the instance.
  kept_states_.push_back(fmu_state);
  state.integers[3] = static_cast<std::int64_t>(kept_states_.size() - 1);
}

void FmuUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.integers.size() != 4) {
    throw std::invalid_argument(Where() + ": not a state of an FMU unit");
  }
  const auto saved_mode = static_cast<Mode>(state.integers[0]);
  const std::int64_t kind = state.integers[3];
  first_dt_ = state.integers[1];
  if (kind == -2) {
    if (instance_ && saved_mode == Mode::kNone) FreeInstance();
    mode_ = saved_mode;
    return;
  }
  if (!instance_ || mode_ == Mode::kBroken || mode_ == Mode::kNone) {
    throw UnitError(Where() +
                    ": cannot restore an FMU state: the FMU is not instantiated (call "
                    "Setup first) or failed fatally");
  }
  const bool v2 = description_.fmi_major == 2;
  int status = 0;
  if (kind == -1) {
    if (state.strings.size() != 1) throw std::invalid_argument(Where() + ": damaged FMU state");
    const std::string& bytes = state.strings[0];
    void* fmu_state = nullptr;
    status = v2 ? static_cast<int>(binary_->f2.DeSerializeFMUstate(instance_, bytes.data(),
                                                                   bytes.size(), &fmu_state))
                : static_cast<int>(binary_->f3.DeserializeFMUState(
                      instance_, reinterpret_cast<const fmi3::Byte*>(bytes.data()), bytes.size(),
                      &fmu_state));
    if (status > 1) {
      throw UnitError(Where() + ": cannot restore the state: " +
                      Describe(v2 ? "fmi2DeSerializeFMUstate" : "fmi3DeserializeFMUState", status));
    }
    status = v2 ? static_cast<int>(binary_->f2.SetFMUstate(instance_, fmu_state))
                : static_cast<int>(binary_->f3.SetFMUState(instance_, fmu_state));
    if (v2) {
      binary_->f2.FreeFMUstate(instance_, &fmu_state);
    } else {
      binary_->f3.FreeFMUState(instance_, &fmu_state);
    }
  } else {
    if (state.integers[2] != id_ || kind < 0 ||
        static_cast<std::size_t>(kind) >= kept_states_.size()) {
      throw UnitError(Where() +
                      ": the FMU cannot serialize its state (canSerializeFMUstate is "
                      "not true): a saved state restores only into the unit that saved it");
    }
    status = v2 ? static_cast<int>(binary_->f2.SetFMUstate(
                      instance_, kept_states_[static_cast<std::size_t>(kind)]))
                : static_cast<int>(binary_->f3.SetFMUState(
                      instance_, kept_states_[static_cast<std::size_t>(kind)]));
  }
  if (status > 1) {
    throw UnitError(Where() + ": cannot restore the state: " +
                    Describe(v2 ? "fmi2SetFMUstate" : "fmi3SetFMUState", status));
  }
  mode_ = saved_mode;
  RememberTunables();
}

}  // namespace linesim::fmu
