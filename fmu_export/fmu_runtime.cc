// The FMI 2.0 co-simulation API over a linesim unit: the binary of every FMU
// `linesim export-fmu` writes (binaries/linux64/<type>.so). fmi2Instantiate
// reads resources/linesim_unit.yaml (a scenario with one unit: its type and
// every parameter value) and builds the unit through the loader and the unit
// registry; the value references are those of MakeLayout, as in the model
// description. Function signatures from "Functional Mock-up Interface for
// Model Exchange and Co-Simulation", version 2.0.4, sections 2.1 and 4.2;
// each is checked against units/fmu/fmi_api.h's pointer type.
//
// Only the fmi2 functions are exported (the library is built with hidden
// visibility and --exclude-libs,ALL): the linesim code inside does not clash
// with a linesim that loads the FMU.

#include <cstdarg>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <memory>
#include <span>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "config/scenario_error.h"
#include "cosim/time.h"
#include "cosim/unit.h"
#include "fmu_export/export_layout.h"
#include "fmu_export/exporter.h"
#include "loader/scenario.h"
#include "units/fmu/fmi_api.h"

namespace fmi2 = linesim::fmu::fmi2;
namespace fmi3 = linesim::fmu::fmi3;

namespace {

namespace cosim = linesim::cosim;
namespace fs = std::filesystem;

enum class Phase { kInstantiated, kInitialization, kStep, kTerminated, kBroken };

struct Instance {
  int version = 2;  // the FMI API it was instantiated through
  std::string name;
  fmi2::CallbackFunctions callbacks{};
  fmi3::LogMessageCallback log3 = nullptr;
  fmi3::InstanceEnvironment environment3 = nullptr;
  bool logging = false;
  std::string resource_file;
  std::unique_ptr<linesim::loader::Scenario> scenario;
  cosim::Unit* unit = nullptr;
  linesim::fmu_export::Layout layout;
  Phase phase = Phase::kInstantiated;
  cosim::TimeNs start = 0;
  cosim::TimeNs stop = 0;
  // Outputs no longer match the inputs and parameters set since they were
  // computed: the next get recomputes them (Initialize in initialization
  // mode, UpdateOutputs in step mode).
  bool stale = true;
  bool has_feedthrough = false;
  cosim::TimeNs last_successful = 0;
};

void Log(const Instance* c, fmi2::Status status, const char* category, const std::string& text) {
  if (c && c->version == 3) {
    // FMI 3.0's status values are FMI 2.0's (without pending).
    if (c->log3)
      c->log3(c->environment3, static_cast<fmi3::Status>(status), category, text.c_str());
  } else if (c && c->callbacks.logger) {
    c->callbacks.logger(c->callbacks.componentEnvironment, c->name.c_str(), status, category, "%s",
                        text.c_str());
  }
}

fmi2::Status Fail(Instance* c, const std::string& text, fmi2::Status status = fmi2::kError) {
  Log(c, status, "logStatusError", text);
  return status;
}

// "file:///a/b", "file:/a/b", "file://localhost/a/b" or a plain path, with
// %XX decoded.
std::string PathOfUri(std::string uri) {
  if (uri.rfind("file://localhost/", 0) == 0) {
    uri = uri.substr(16);
  } else if (uri.rfind("file://", 0) == 0) {
    uri = uri.substr(7);
  } else if (uri.rfind("file:", 0) == 0) {
    uri = uri.substr(5);
  }
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size()) {
      out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

std::string ReadText(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// Builds (or rebuilds, for fmi2Reset) the unit from the resource file.
void Build(Instance& c) {
  try {
    auto scenario =
        std::make_unique<linesim::loader::Scenario>(linesim::loader::LoadScenario(c.resource_file));
    if (scenario->system->unit_count() != 1) {
      throw std::runtime_error(c.resource_file + " must hold exactly one unit");
    }
    c.scenario = std::move(scenario);
  } catch (const linesim::config::ScenarioError& e) {
    throw std::runtime_error(std::string("cannot build the unit: ") + e.what());
  }
  c.unit = &c.scenario->system->unit(0);
  c.layout = linesim::fmu_export::MakeLayout(c.unit->variables());
  c.has_feedthrough = false;
  for (const auto& info : c.unit->variables().infos()) {
    if (info.causality == cosim::Causality::kOutput && !info.depends_on.empty()) {
      c.has_feedthrough = true;
    }
  }
  c.phase = Phase::kInstantiated;
  c.start = c.stop = c.last_successful = 0;
  c.stale = true;
}

// Reads the resource files of the folder `resources`, checks the guid /
// instantiation token against them and builds the unit.
void Open(Instance& c, const std::string& resources, const char* token) {
  c.resource_file = (fs::path(resources) / linesim::fmu_export::kResourceFile).string();
  const std::string text = ReadText(c.resource_file);
  const fs::path scene_file = fs::path(resources) / linesim::fmu_export::kSceneFile;
  const std::string scene = fs::exists(scene_file) ? ReadText(scene_file.string()) : "";
  const std::string expected = linesim::fmu_export::GuidOfResources(text, scene);
  if (!token || expected != token) {
    throw std::runtime_error(std::string(c.version == 2 ? "guid " : "instantiationToken ") +
                             (token ? token : "(null)") + " does not match this FMU's " + expected);
  }
  Build(c);
}

Instance* Of(fmi2::Component c) { return static_cast<Instance*>(c); }

// Checks a value reference; on a bad one logs and returns null.
const linesim::fmu_export::ExportedVariable* Variable(Instance* c, fmi2::ValueReference vr,
                                                      cosim::VarType type) {
  if (vr >= c->layout.variables.size() || c->layout.variables[vr].type != type) {
    Fail(c, "value reference " + std::to_string(vr) + " is no " +
                std::string(cosim::ToString(type)) + " variable of this FMU");
    return nullptr;
  }
  return &c->layout.variables[vr];
}

// Brings outputs up to date with what was set before a get.
void Refresh(Instance* c) {
  if (!c->stale) return;
  if (c->phase == Phase::kInitialization) {
    c->unit->Initialize();
  } else if (c->phase == Phase::kStep) {
    if (c->has_feedthrough) c->unit->UpdateOutputs();
  } else {
    return;  // before initialization the outputs are the start values
  }
  c->stale = false;
}

// A set changes outputs only through inputs (and, in initialization mode,
// parameters).
void MarkSetRef(Instance* c, cosim::ValueRef ref) {
  const auto causality = c->unit->variables().info(ref).causality;
  if (causality == cosim::Causality::kInput ||
      (causality == cosim::Causality::kParameter && c->phase != Phase::kStep)) {
    c->stale = true;
  }
}

void MarkSet(Instance* c, const linesim::fmu_export::ExportedVariable& v) {
  const auto causality = c->unit->variables().info(v.ref).causality;
  if (causality == cosim::Causality::kInput ||
      (causality == cosim::Causality::kParameter && c->phase != Phase::kStep)) {
    c->stale = true;
  }
}

template <typename F>
fmi2::Status Guard(Instance* c, const char* function, F&& body) {
  if (!c) return fmi2::kError;
  if (c->phase == Phase::kBroken) {
    return Fail(c, std::string(function) + ": the instance failed before and must be reset");
  }
  try {
    return body();
  } catch (const std::exception& e) {
    return Fail(c, std::string(function) + ": " + e.what());
  }
}

struct StateBox {
  cosim::UnitState state;
};

}  // namespace

#define LINESIM_FMI_EXPORT extern "C" __attribute__((visibility("default")))

LINESIM_FMI_EXPORT const char* fmi2GetTypesPlatform() { return "default"; }
LINESIM_FMI_EXPORT const char* fmi2GetVersion() { return "2.0"; }

LINESIM_FMI_EXPORT fmi2::Status fmi2SetDebugLogging(fmi2::Component c, fmi2::Boolean on,
                                                    std::size_t, const fmi2::String[]) {
  if (!c) return fmi2::kError;
  Of(c)->logging = on != fmi2::kFalse;
  return fmi2::kOK;
}

LINESIM_FMI_EXPORT fmi2::Component fmi2Instantiate(fmi2::String instance_name, fmi2::Type type,
                                                   fmi2::String guid,
                                                   fmi2::String resource_location,
                                                   const fmi2::CallbackFunctions* functions,
                                                   fmi2::Boolean, fmi2::Boolean logging_on) {
  auto c = std::make_unique<Instance>();
  c->name = instance_name ? instance_name : "";
  if (functions) c->callbacks = *functions;
  c->logging = logging_on != fmi2::kFalse;
  try {
    if (type != fmi2::kCoSimulation) {
      throw std::runtime_error("this FMU is co-simulation only (fmi2CoSimulation)");
    }
    if (!resource_location) throw std::runtime_error("no fmuResourceLocation given");
    Open(*c, PathOfUri(resource_location), guid);
  } catch (const std::exception& e) {
    Fail(c.get(), std::string("fmi2Instantiate: ") + e.what());
    return nullptr;
  }
  return c.release();
}

LINESIM_FMI_EXPORT void fmi2FreeInstance(fmi2::Component c) { delete Of(c); }

LINESIM_FMI_EXPORT fmi2::Status fmi2SetupExperiment(fmi2::Component component, fmi2::Boolean,
                                                    fmi2::Real, fmi2::Real start_time,
                                                    fmi2::Boolean stop_time_defined,
                                                    fmi2::Real stop_time) {
  Instance* c = Of(component);
  return Guard(c, "fmi2SetupExperiment", [&] {
    if (c->phase != Phase::kInstantiated)
      return Fail(c, "fmi2SetupExperiment: not after instantiation");
    c->start = cosim::SecondsToNs(start_time);
    c->stop =
        stop_time_defined ? cosim::SecondsToNs(stop_time) : cosim::kNsPerSecond * 1'000'000'000LL;
    c->last_successful = c->start;
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2EnterInitializationMode(fmi2::Component component) {
  Instance* c = Of(component);
  return Guard(c, "fmi2EnterInitializationMode", [&] {
    if (c->phase != Phase::kInstantiated) {
      return Fail(c, "fmi2EnterInitializationMode: not after instantiation");
    }
    c->unit->Setup(c->start, c->stop);
    c->phase = Phase::kInitialization;
    c->stale = true;
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2ExitInitializationMode(fmi2::Component component) {
  Instance* c = Of(component);
  return Guard(c, "fmi2ExitInitializationMode", [&] {
    if (c->phase != Phase::kInitialization) {
      return Fail(c, "fmi2ExitInitializationMode: not in initialization mode");
    }
    try {
      Refresh(c);
    } catch (...) {
      c->phase = Phase::kBroken;
      throw;
    }
    c->unit->variables().Lock();
    c->phase = Phase::kStep;
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2Terminate(fmi2::Component component) {
  Instance* c = Of(component);
  return Guard(c, "fmi2Terminate", [&] {
    c->unit->Terminate();
    c->phase = Phase::kTerminated;
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2Reset(fmi2::Component component) {
  Instance* c = Of(component);
  if (!c) return fmi2::kError;
  try {
    Build(*c);
    return fmi2::kOK;
  } catch (const std::exception& e) {
    c->phase = Phase::kBroken;
    return Fail(c, std::string("fmi2Reset: ") + e.what(), fmi2::kFatal);
  }
}

// --- get / set ----------------------------------------------------------

LINESIM_FMI_EXPORT fmi2::Status fmi2GetReal(fmi2::Component component,
                                            const fmi2::ValueReference vr[], std::size_t n,
                                            fmi2::Real value[]) {
  Instance* c = Of(component);
  return Guard(c, "fmi2GetReal", [&] {
    Refresh(c);
    const auto& table = c->unit->variables();
    for (std::size_t k = 0; k < n; ++k) {
      const auto* v = Variable(c, vr[k], cosim::VarType::kReal);
      if (!v) return fmi2::kError;
      value[k] = v->is_element ? table.GetRealElement(v->ref, v->element) : table.GetReal(v->ref);
    }
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2GetInteger(fmi2::Component component,
                                               const fmi2::ValueReference vr[], std::size_t n,
                                               fmi2::Integer value[]) {
  Instance* c = Of(component);
  return Guard(c, "fmi2GetInteger", [&] {
    Refresh(c);
    for (std::size_t k = 0; k < n; ++k) {
      const auto* v = Variable(c, vr[k], cosim::VarType::kInteger);
      if (!v) return fmi2::kError;
      const std::int64_t x = c->unit->variables().GetInteger(v->ref);
      if (x < INT32_MIN || x > INT32_MAX) {
        return Fail(c, "fmi2GetInteger: " + v->name + " = " + std::to_string(x) +
                           " does not fit FMI 2.0's 32-bit Integer");
      }
      value[k] = static_cast<fmi2::Integer>(x);
    }
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2GetBoolean(fmi2::Component component,
                                               const fmi2::ValueReference vr[], std::size_t n,
                                               fmi2::Boolean value[]) {
  Instance* c = Of(component);
  return Guard(c, "fmi2GetBoolean", [&] {
    Refresh(c);
    for (std::size_t k = 0; k < n; ++k) {
      const auto* v = Variable(c, vr[k], cosim::VarType::kBoolean);
      if (!v) return fmi2::kError;
      value[k] = c->unit->variables().GetBoolean(v->ref) ? fmi2::kTrue : fmi2::kFalse;
    }
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2GetString(fmi2::Component component,
                                              const fmi2::ValueReference vr[], std::size_t n,
                                              fmi2::String value[]) {
  Instance* c = Of(component);
  return Guard(c, "fmi2GetString", [&] {
    Refresh(c);
    for (std::size_t k = 0; k < n; ++k) {
      const auto* v = Variable(c, vr[k], cosim::VarType::kString);
      if (!v) return fmi2::kError;
      // Valid until the variable changes (the standard asks until the next call).
      value[k] = c->unit->variables().GetString(v->ref).c_str();
    }
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2SetReal(fmi2::Component component,
                                            const fmi2::ValueReference vr[], std::size_t n,
                                            const fmi2::Real value[]) {
  Instance* c = Of(component);
  return Guard(c, "fmi2SetReal", [&] {
    auto& table = c->unit->variables();
    for (std::size_t k = 0; k < n; ++k) {
      const auto* v = Variable(c, vr[k], cosim::VarType::kReal);
      if (!v) return fmi2::kError;
      if (v->is_element) {
        table.SetRealElement(v->ref, v->element, value[k]);
      } else {
        table.SetReal(v->ref, value[k]);
      }
      MarkSet(c, *v);
    }
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2SetInteger(fmi2::Component component,
                                               const fmi2::ValueReference vr[], std::size_t n,
                                               const fmi2::Integer value[]) {
  Instance* c = Of(component);
  return Guard(c, "fmi2SetInteger", [&] {
    for (std::size_t k = 0; k < n; ++k) {
      const auto* v = Variable(c, vr[k], cosim::VarType::kInteger);
      if (!v) return fmi2::kError;
      c->unit->variables().SetInteger(v->ref, value[k]);
      MarkSet(c, *v);
    }
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2SetBoolean(fmi2::Component component,
                                               const fmi2::ValueReference vr[], std::size_t n,
                                               const fmi2::Boolean value[]) {
  Instance* c = Of(component);
  return Guard(c, "fmi2SetBoolean", [&] {
    for (std::size_t k = 0; k < n; ++k) {
      const auto* v = Variable(c, vr[k], cosim::VarType::kBoolean);
      if (!v) return fmi2::kError;
      c->unit->variables().SetBoolean(v->ref, value[k] != fmi2::kFalse);
      MarkSet(c, *v);
    }
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2SetString(fmi2::Component component,
                                              const fmi2::ValueReference vr[], std::size_t n,
                                              const fmi2::String value[]) {
  Instance* c = Of(component);
  return Guard(c, "fmi2SetString", [&] {
    for (std::size_t k = 0; k < n; ++k) {
      const auto* v = Variable(c, vr[k], cosim::VarType::kString);
      if (!v) return fmi2::kError;
      c->unit->variables().SetString(v->ref, value[k] ? value[k] : "");
      MarkSet(c, *v);
    }
    return fmi2::kOK;
  });
}

// --- state --------------------------------------------------------------

LINESIM_FMI_EXPORT fmi2::Status fmi2GetFMUstate(fmi2::Component component, fmi2::FMUstate* state) {
  Instance* c = Of(component);
  return Guard(c, "fmi2GetFMUstate", [&] {
    if (!state) return Fail(c, "fmi2GetFMUstate: no state pointer");
    auto* box = static_cast<StateBox*>(*state);
    if (!box) {
      box = new StateBox;
      *state = box;
    }
    box->state = c->unit->SaveState();
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2SetFMUstate(fmi2::Component component, fmi2::FMUstate state) {
  Instance* c = Of(component);
  return Guard(c, "fmi2SetFMUstate", [&] {
    if (!state) return Fail(c, "fmi2SetFMUstate: no state");
    c->unit->RestoreState(static_cast<StateBox*>(state)->state);
    c->stale = false;  // the restored outputs are those saved
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2FreeFMUstate(fmi2::Component component, fmi2::FMUstate* state) {
  if (!component || !state) return fmi2::kError;
  delete static_cast<StateBox*>(*state);
  *state = nullptr;
  return fmi2::kOK;
}

LINESIM_FMI_EXPORT fmi2::Status fmi2SerializedFMUstateSize(fmi2::Component component,
                                                           fmi2::FMUstate state,
                                                           std::size_t* size) {
  Instance* c = Of(component);
  return Guard(c, "fmi2SerializedFMUstateSize", [&] {
    if (!state || !size) return Fail(c, "fmi2SerializedFMUstateSize: no state");
    *size = linesim::fmu_export::SerializeState(static_cast<StateBox*>(state)->state).size();
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2SerializeFMUstate(fmi2::Component component,
                                                      fmi2::FMUstate state, fmi2::Byte bytes[],
                                                      std::size_t size) {
  Instance* c = Of(component);
  return Guard(c, "fmi2SerializeFMUstate", [&] {
    if (!state || !bytes) return Fail(c, "fmi2SerializeFMUstate: no state");
    const auto data = linesim::fmu_export::SerializeState(static_cast<StateBox*>(state)->state);
    if (size < data.size()) {
      return Fail(c, "fmi2SerializeFMUstate: " + std::to_string(size) + " bytes given, " +
                         std::to_string(data.size()) + " needed");
    }
    std::memcpy(bytes, data.data(), data.size());
    return fmi2::kOK;
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2DeSerializeFMUstate(fmi2::Component component,
                                                        const fmi2::Byte bytes[], std::size_t size,
                                                        fmi2::FMUstate* state) {
  Instance* c = Of(component);
  return Guard(c, "fmi2DeSerializeFMUstate", [&] {
    if (!bytes || !state) return Fail(c, "fmi2DeSerializeFMUstate: no bytes or state pointer");
    auto restored = linesim::fmu_export::DeserializeState(bytes, size);
    if (restored.type_name != c->unit->type_name()) {
      return Fail(c, "fmi2DeSerializeFMUstate: a state of a " + restored.type_name +
                         " unit, this FMU is a " + c->unit->type_name());
    }
    auto* box = static_cast<StateBox*>(*state);
    if (!box) {
      box = new StateBox;
      *state = box;
    }
    box->state = std::move(restored);
    return fmi2::kOK;
  });
}

// --- not provided (the model description says so) -----------------------

LINESIM_FMI_EXPORT fmi2::Status fmi2GetDirectionalDerivative(
    fmi2::Component c, const fmi2::ValueReference[], std::size_t, const fmi2::ValueReference[],
    std::size_t, const fmi2::Real[], fmi2::Real[]) {
  return Fail(Of(c),
              "fmi2GetDirectionalDerivative: not provided (providesDirectionalDerivative=false)");
}

LINESIM_FMI_EXPORT fmi2::Status fmi2SetRealInputDerivatives(fmi2::Component c,
                                                            const fmi2::ValueReference[],
                                                            std::size_t, const fmi2::Integer[],
                                                            const fmi2::Real[]) {
  return Fail(Of(c), "fmi2SetRealInputDerivatives: not provided (canInterpolateInputs=false)");
}

LINESIM_FMI_EXPORT fmi2::Status fmi2GetRealOutputDerivatives(fmi2::Component c,
                                                             const fmi2::ValueReference[],
                                                             std::size_t, const fmi2::Integer[],
                                                             fmi2::Real[]) {
  return Fail(Of(c), "fmi2GetRealOutputDerivatives: not provided (maxOutputDerivativeOrder=0)");
}

LINESIM_FMI_EXPORT fmi2::Status fmi2CancelStep(fmi2::Component c) {
  return Fail(Of(c), "fmi2CancelStep: doStep is synchronous, there is nothing to cancel");
}

// --- stepping -------------------------------------------------------------

LINESIM_FMI_EXPORT fmi2::Status fmi2DoStep(fmi2::Component component, fmi2::Real t, fmi2::Real h,
                                           fmi2::Boolean) {
  Instance* c = Of(component);
  return Guard(c, "fmi2DoStep", [&] {
    if (c->phase != Phase::kStep) return Fail(c, "fmi2DoStep: not in step mode");
    const cosim::TimeNs t_ns = cosim::SecondsToNs(t);
    const cosim::TimeNs dt_ns = cosim::SecondsToNs(h);
    if (dt_ns <= 0) {
      return Fail(c, "fmi2DoStep: step size " + std::to_string(h) + " s is not positive");
    }
    const cosim::StepResult result = c->unit->DoStep(t_ns, dt_ns);
    c->stale = false;
    switch (result) {
      case cosim::StepResult::kOk:
        c->last_successful = t_ns + dt_ns;
        return fmi2::kOK;
      case cosim::StepResult::kDiscard:
        Log(c, fmi2::kDiscard, "logStatusDiscard", c->unit->last_error());
        return fmi2::kDiscard;
      case cosim::StepResult::kError:
        break;
    }
    c->phase = Phase::kBroken;
    return Fail(c,
                "fmi2DoStep at t = " + cosim::FormatSeconds(t_ns) + " s: " + c->unit->last_error());
  });
}

LINESIM_FMI_EXPORT fmi2::Status fmi2GetStatus(fmi2::Component c, fmi2::StatusKind, fmi2::Status*) {
  return Fail(Of(c), "fmi2GetStatus: doStep never returns fmi2Pending");
}

LINESIM_FMI_EXPORT fmi2::Status fmi2GetRealStatus(fmi2::Component component, fmi2::StatusKind kind,
                                                  fmi2::Real* value) {
  Instance* c = Of(component);
  if (!c || !value) return fmi2::kError;
  if (kind != fmi2::kLastSuccessfulTime) {
    return Fail(c, "fmi2GetRealStatus: only fmi2LastSuccessfulTime is provided");
  }
  *value = cosim::NsToSeconds(c->last_successful);
  return fmi2::kOK;
}

LINESIM_FMI_EXPORT fmi2::Status fmi2GetIntegerStatus(fmi2::Component c, fmi2::StatusKind,
                                                     fmi2::Integer*) {
  return Fail(Of(c), "fmi2GetIntegerStatus: no integer status is provided");
}

LINESIM_FMI_EXPORT fmi2::Status fmi2GetBooleanStatus(fmi2::Component component,
                                                     fmi2::StatusKind kind, fmi2::Boolean* value) {
  Instance* c = Of(component);
  if (!c || !value) return fmi2::kError;
  if (kind != fmi2::kTerminated) {
    return Fail(c, "fmi2GetBooleanStatus: only fmi2Terminated is provided");
  }
  *value = fmi2::kFalse;  // the unit never asks to end the simulation
  return fmi2::kOK;
}

LINESIM_FMI_EXPORT fmi2::Status fmi2GetStringStatus(fmi2::Component c, fmi2::StatusKind,
                                                    fmi2::String*) {
  return Fail(Of(c), "fmi2GetStringStatus: doStep never returns fmi2Pending");
}

// The signatures agree with the importer's pointer types (written from the
// same standard).
static_assert(std::is_same_v<decltype(&fmi2Instantiate), fmi2::InstantiateTYPE>);
static_assert(std::is_same_v<decltype(&fmi2DoStep), fmi2::DoStepTYPE>);
static_assert(std::is_same_v<decltype(&fmi2GetReal), fmi2::GetRealTYPE>);
static_assert(std::is_same_v<decltype(&fmi2SetReal), fmi2::SetRealTYPE>);
static_assert(std::is_same_v<decltype(&fmi2GetString), fmi2::GetStringTYPE>);
static_assert(std::is_same_v<decltype(&fmi2SetString), fmi2::SetStringTYPE>);
static_assert(std::is_same_v<decltype(&fmi2SetupExperiment), fmi2::SetupExperimentTYPE>);
static_assert(std::is_same_v<decltype(&fmi2GetFMUstate), fmi2::GetFMUstateTYPE>);
static_assert(std::is_same_v<decltype(&fmi2SerializeFMUstate), fmi2::SerializeFMUstateTYPE>);
static_assert(std::is_same_v<decltype(&fmi2DeSerializeFMUstate), fmi2::DeSerializeFMUstateTYPE>);
static_assert(std::is_same_v<decltype(&fmi2GetRealStatus), fmi2::GetRealStatusTYPE>);
static_assert(std::is_same_v<decltype(&fmi2GetBooleanStatus), fmi2::GetBooleanStatusTYPE>);

// ===========================================================================
// FMI 3.0 co-simulation ("Functional Mock-up Interface Specification",
// version 3.0, sections 2.2 and 4.2). The value reference of a variable is
// its index in the unit's table; a Real array is one Float64 variable with
// a fixed dimension. Every function of the standard is exported; those of
// model exchange, scheduled execution, clocks and event mode refuse.
// ===========================================================================

namespace {

fmi3::Status S3(fmi2::Status s) { return static_cast<fmi3::Status>(s); }
Instance* Of3(fmi3::Instance c) { return static_cast<Instance*>(c); }

fmi3::Status Refuse3(fmi3::Instance c, const std::string& what) { return S3(Fail(Of3(c), what)); }

// A get or set of a type this FMU has no variable of: fine for none.
fmi3::Status NoVariables3(fmi3::Instance c, const char* function, std::size_t n) {
  if (!c) return fmi3::kError;
  if (n == 0) return fmi3::kOK;
  return Refuse3(c, std::string(function) + ": this FMU has no variable of that type");
}

// The table variable `vr` names if it has one of `types`; else logs.
const cosim::VariableInfo* Variable3(Instance* c, fmi3::ValueReference vr,
                                     std::initializer_list<cosim::VarType> types,
                                     const char* function) {
  const auto& table = c->unit->variables();
  if (vr < table.size()) {
    const auto& info = table.info(vr);
    for (auto t : types) {
      if (info.type == t) return &info;
    }
  }
  Fail(c, std::string(function) + ": value reference " + std::to_string(vr) +
              " names no variable of that type");
  return nullptr;
}

fmi2::Status CountMismatch(Instance* c, const char* function, std::size_t used, std::size_t n) {
  return Fail(c, std::string(function) + ": the value references have " + std::to_string(used) +
                     " values, nValues is " + std::to_string(n));
}

}  // namespace

LINESIM_FMI_EXPORT const char* fmi3GetVersion() { return "3.0"; }

LINESIM_FMI_EXPORT fmi3::Status fmi3SetDebugLogging(fmi3::Instance c, fmi3::Boolean on, std::size_t,
                                                    const fmi3::String[]) {
  if (!c) return fmi3::kError;
  Of3(c)->logging = on;
  return fmi3::kOK;
}

LINESIM_FMI_EXPORT fmi3::Instance fmi3InstantiateModelExchange(
    fmi3::String, fmi3::String, fmi3::String, fmi3::Boolean, fmi3::Boolean,
    fmi3::InstanceEnvironment environment, fmi3::LogMessageCallback log) {
  if (log) log(environment, fmi3::kError, "logStatusError", "this FMU is co-simulation only");
  return nullptr;
}

LINESIM_FMI_EXPORT fmi3::Instance fmi3InstantiateCoSimulation(
    fmi3::String instance_name, fmi3::String token, fmi3::String resource_path, fmi3::Boolean,
    fmi3::Boolean logging_on, fmi3::Boolean event_mode_used, fmi3::Boolean,
    const fmi3::ValueReference[], std::size_t n_required_intermediate,
    fmi3::InstanceEnvironment environment, fmi3::LogMessageCallback log,
    fmi3::IntermediateUpdateCallback) {
  auto c = std::make_unique<Instance>();
  c->version = 3;
  c->name = instance_name ? instance_name : "";
  c->log3 = log;
  c->environment3 = environment;
  c->logging = logging_on;
  try {
    if (event_mode_used)
      throw std::runtime_error("event mode is not provided (hasEventMode=false)");
    if (n_required_intermediate > 0) {
      throw std::runtime_error("intermediate variables are not provided");
    }
    if (!resource_path) throw std::runtime_error("no resourcePath given");
    Open(*c, resource_path, token);
  } catch (const std::exception& e) {
    Fail(c.get(), std::string("fmi3InstantiateCoSimulation: ") + e.what());
    return nullptr;
  }
  return c.release();
}

using ClockUpdateCallback = void (*)(fmi3::InstanceEnvironment);
using LockPreemptionCallback = void (*)();
using UnlockPreemptionCallback = void (*)();

LINESIM_FMI_EXPORT fmi3::Instance fmi3InstantiateScheduledExecution(
    fmi3::String, fmi3::String, fmi3::String, fmi3::Boolean, fmi3::Boolean,
    fmi3::InstanceEnvironment environment, fmi3::LogMessageCallback log, ClockUpdateCallback,
    LockPreemptionCallback, UnlockPreemptionCallback) {
  if (log) log(environment, fmi3::kError, "logStatusError", "this FMU is co-simulation only");
  return nullptr;
}

LINESIM_FMI_EXPORT void fmi3FreeInstance(fmi3::Instance c) { delete Of3(c); }

LINESIM_FMI_EXPORT fmi3::Status fmi3EnterInitializationMode(fmi3::Instance instance, fmi3::Boolean,
                                                            fmi3::Float64, fmi3::Float64 start_time,
                                                            fmi3::Boolean stop_time_defined,
                                                            fmi3::Float64 stop_time) {
  const fmi2::Status s =
      fmi2SetupExperiment(instance, fmi2::kFalse, 0.0, start_time,
                          stop_time_defined ? fmi2::kTrue : fmi2::kFalse, stop_time);
  if (s != fmi2::kOK) return S3(s);
  return S3(fmi2EnterInitializationMode(instance));
}

LINESIM_FMI_EXPORT fmi3::Status fmi3ExitInitializationMode(fmi3::Instance c) {
  return S3(fmi2ExitInitializationMode(c));
}
LINESIM_FMI_EXPORT fmi3::Status fmi3EnterEventMode(fmi3::Instance c) {
  return Refuse3(c, "fmi3EnterEventMode: event mode is not provided (hasEventMode=false)");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3Terminate(fmi3::Instance c) { return S3(fmi2Terminate(c)); }
LINESIM_FMI_EXPORT fmi3::Status fmi3Reset(fmi3::Instance c) { return S3(fmi2Reset(c)); }

// --- get / set ----------------------------------------------------------

LINESIM_FMI_EXPORT fmi3::Status fmi3GetFloat64(fmi3::Instance instance,
                                               const fmi3::ValueReference vr[], std::size_t nvr,
                                               fmi3::Float64 values[], std::size_t n) {
  Instance* c = Of3(instance);
  return S3(Guard(c, "fmi3GetFloat64", [&] {
    Refresh(c);
    const auto& table = c->unit->variables();
    std::size_t k = 0;
    for (std::size_t i = 0; i < nvr; ++i) {
      const auto* info = Variable3(c, vr[i], {cosim::VarType::kReal, cosim::VarType::kRealArray},
                                   "fmi3GetFloat64");
      if (!info) return fmi2::kError;
      const auto v = table.RealValues(info->ref);
      if (k + v.size() > n) return CountMismatch(c, "fmi3GetFloat64", k + v.size(), n);
      for (double x : v) values[k++] = x;
    }
    return k == n ? fmi2::kOK : CountMismatch(c, "fmi3GetFloat64", k, n);
  }));
}

LINESIM_FMI_EXPORT fmi3::Status fmi3SetFloat64(fmi3::Instance instance,
                                               const fmi3::ValueReference vr[], std::size_t nvr,
                                               const fmi3::Float64 values[], std::size_t n) {
  Instance* c = Of3(instance);
  return S3(Guard(c, "fmi3SetFloat64", [&] {
    auto& table = c->unit->variables();
    std::size_t k = 0;
    for (std::size_t i = 0; i < nvr; ++i) {
      const auto* info = Variable3(c, vr[i], {cosim::VarType::kReal, cosim::VarType::kRealArray},
                                   "fmi3SetFloat64");
      if (!info) return fmi2::kError;
      if (k + info->size > n) return CountMismatch(c, "fmi3SetFloat64", k + info->size, n);
      if (info->type == cosim::VarType::kReal) {
        table.SetReal(info->ref, values[k]);
      } else {
        table.SetRealArray(info->ref, std::span<const double>(values + k, info->size));
      }
      k += info->size;
      MarkSetRef(c, info->ref);
    }
    return k == n ? fmi2::kOK : CountMismatch(c, "fmi3SetFloat64", k, n);
  }));
}

namespace {

// A linesim Integer of the FMI 3.0 type `int64` selects (IsInt64In3: Int64
// when its declared range is wider than 32 bits, else Int32), or nothing
// after reporting: each variable is served by the functions of its
// declared type only.
const cosim::VariableInfo* Integer3(Instance* c, fmi3::ValueReference vr, bool int64,
                                    const char* function) {
  const auto* info = Variable3(c, vr, {cosim::VarType::kInteger}, function);
  if (info && linesim::fmu_export::IsInt64In3(*info) != int64) {
    Fail(c, std::string(function) + ": value reference " + std::to_string(vr) + " is '" +
                info->name + "', an " + (int64 ? "Int32" : "Int64") + " variable");
    return nullptr;
  }
  return info;
}

template <typename T>
fmi2::Status GetInteger3(fmi3::Instance instance, const fmi3::ValueReference vr[], std::size_t nvr,
                         T values[], std::size_t n, const char* function) {
  Instance* c = Of3(instance);
  constexpr bool kInt64 = sizeof(T) == 8;
  return Guard(c, function, [&] {
    if (n != nvr) return CountMismatch(c, function, nvr, n);
    Refresh(c);
    for (std::size_t i = 0; i < nvr; ++i) {
      const auto* info = Integer3(c, vr[i], kInt64, function);
      if (!info) return fmi2::kError;
      const std::int64_t x = c->unit->variables().GetInteger(info->ref);
      if (!kInt64 && (x < INT32_MIN || x > INT32_MAX)) {
        return Fail(c, std::string(function) + ": " + info->name + " = " + std::to_string(x) +
                           " does not fit 32 bits");
      }
      values[i] = static_cast<T>(x);
    }
    return fmi2::kOK;
  });
}

template <typename T>
fmi2::Status SetInteger3(fmi3::Instance instance, const fmi3::ValueReference vr[], std::size_t nvr,
                         const T values[], std::size_t n, const char* function) {
  Instance* c = Of3(instance);
  return Guard(c, function, [&] {
    if (n != nvr) return CountMismatch(c, function, nvr, n);
    for (std::size_t i = 0; i < nvr; ++i) {
      const auto* info = Integer3(c, vr[i], sizeof(T) == 8, function);
      if (!info) return fmi2::kError;
      c->unit->variables().SetInteger(info->ref, values[i]);
      MarkSetRef(c, info->ref);
    }
    return fmi2::kOK;
  });
}

}  // namespace

LINESIM_FMI_EXPORT fmi3::Status fmi3GetInt32(fmi3::Instance instance,
                                             const fmi3::ValueReference vr[], std::size_t nvr,
                                             fmi3::Int32 values[], std::size_t n) {
  return S3(GetInteger3(instance, vr, nvr, values, n, "fmi3GetInt32"));
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetInt32(fmi3::Instance instance,
                                             const fmi3::ValueReference vr[], std::size_t nvr,
                                             const fmi3::Int32 values[], std::size_t n) {
  return S3(SetInteger3(instance, vr, nvr, values, n, "fmi3SetInt32"));
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetInt64(fmi3::Instance instance,
                                             const fmi3::ValueReference vr[], std::size_t nvr,
                                             std::int64_t values[], std::size_t n) {
  return S3(GetInteger3(instance, vr, nvr, values, n, "fmi3GetInt64"));
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetInt64(fmi3::Instance instance,
                                             const fmi3::ValueReference vr[], std::size_t nvr,
                                             const std::int64_t values[], std::size_t n) {
  return S3(SetInteger3(instance, vr, nvr, values, n, "fmi3SetInt64"));
}

LINESIM_FMI_EXPORT fmi3::Status fmi3GetBoolean(fmi3::Instance instance,
                                               const fmi3::ValueReference vr[], std::size_t nvr,
                                               fmi3::Boolean values[], std::size_t n) {
  Instance* c = Of3(instance);
  return S3(Guard(c, "fmi3GetBoolean", [&] {
    if (n != nvr) return CountMismatch(c, "fmi3GetBoolean", nvr, n);
    Refresh(c);
    for (std::size_t i = 0; i < nvr; ++i) {
      const auto* info = Variable3(c, vr[i], {cosim::VarType::kBoolean}, "fmi3GetBoolean");
      if (!info) return fmi2::kError;
      values[i] = c->unit->variables().GetBoolean(info->ref);
    }
    return fmi2::kOK;
  }));
}

LINESIM_FMI_EXPORT fmi3::Status fmi3SetBoolean(fmi3::Instance instance,
                                               const fmi3::ValueReference vr[], std::size_t nvr,
                                               const fmi3::Boolean values[], std::size_t n) {
  Instance* c = Of3(instance);
  return S3(Guard(c, "fmi3SetBoolean", [&] {
    if (n != nvr) return CountMismatch(c, "fmi3SetBoolean", nvr, n);
    for (std::size_t i = 0; i < nvr; ++i) {
      const auto* info = Variable3(c, vr[i], {cosim::VarType::kBoolean}, "fmi3SetBoolean");
      if (!info) return fmi2::kError;
      c->unit->variables().SetBoolean(info->ref, values[i]);
      MarkSetRef(c, info->ref);
    }
    return fmi2::kOK;
  }));
}

LINESIM_FMI_EXPORT fmi3::Status fmi3GetString(fmi3::Instance instance,
                                              const fmi3::ValueReference vr[], std::size_t nvr,
                                              fmi3::String values[], std::size_t n) {
  Instance* c = Of3(instance);
  return S3(Guard(c, "fmi3GetString", [&] {
    if (n != nvr) return CountMismatch(c, "fmi3GetString", nvr, n);
    Refresh(c);
    for (std::size_t i = 0; i < nvr; ++i) {
      const auto* info = Variable3(c, vr[i], {cosim::VarType::kString}, "fmi3GetString");
      if (!info) return fmi2::kError;
      values[i] = c->unit->variables().GetString(info->ref).c_str();
    }
    return fmi2::kOK;
  }));
}

LINESIM_FMI_EXPORT fmi3::Status fmi3SetString(fmi3::Instance instance,
                                              const fmi3::ValueReference vr[], std::size_t nvr,
                                              const fmi3::String values[], std::size_t n) {
  Instance* c = Of3(instance);
  return S3(Guard(c, "fmi3SetString", [&] {
    if (n != nvr) return CountMismatch(c, "fmi3SetString", nvr, n);
    for (std::size_t i = 0; i < nvr; ++i) {
      const auto* info = Variable3(c, vr[i], {cosim::VarType::kString}, "fmi3SetString");
      if (!info) return fmi2::kError;
      c->unit->variables().SetString(info->ref, values[i] ? values[i] : "");
      MarkSetRef(c, info->ref);
    }
    return fmi2::kOK;
  }));
}

// Types no linesim variable has.
#define LINESIM_FMI3_NO_TYPE(Name, T)                                                           \
  LINESIM_FMI_EXPORT fmi3::Status fmi3Get##Name(fmi3::Instance c, const fmi3::ValueReference[], \
                                                std::size_t nvr, T[], std::size_t) {            \
    return NoVariables3(c, "fmi3Get" #Name, nvr);                                               \
  }                                                                                             \
  LINESIM_FMI_EXPORT fmi3::Status fmi3Set##Name(fmi3::Instance c, const fmi3::ValueReference[], \
                                                std::size_t nvr, const T[], std::size_t) {      \
    return NoVariables3(c, "fmi3Set" #Name, nvr);                                               \
  }
LINESIM_FMI3_NO_TYPE(Float32, float)
LINESIM_FMI3_NO_TYPE(Int8, std::int8_t)
LINESIM_FMI3_NO_TYPE(UInt8, std::uint8_t)
LINESIM_FMI3_NO_TYPE(Int16, std::int16_t)
LINESIM_FMI3_NO_TYPE(UInt16, std::uint16_t)
LINESIM_FMI3_NO_TYPE(UInt32, std::uint32_t)
LINESIM_FMI3_NO_TYPE(UInt64, std::uint64_t)
#undef LINESIM_FMI3_NO_TYPE

using Binary3 = const fmi3::Byte*;
using Clock3 = bool;
LINESIM_FMI_EXPORT fmi3::Status fmi3GetBinary(fmi3::Instance c, const fmi3::ValueReference[],
                                              std::size_t nvr, std::size_t[], Binary3[],
                                              std::size_t) {
  return NoVariables3(c, "fmi3GetBinary", nvr);
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetBinary(fmi3::Instance c, const fmi3::ValueReference[],
                                              std::size_t nvr, const std::size_t[], const Binary3[],
                                              std::size_t) {
  return NoVariables3(c, "fmi3SetBinary", nvr);
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetClock(fmi3::Instance c, const fmi3::ValueReference[],
                                             std::size_t nvr, Clock3[]) {
  return NoVariables3(c, "fmi3GetClock", nvr);
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetClock(fmi3::Instance c, const fmi3::ValueReference[],
                                             std::size_t nvr, const Clock3[]) {
  return NoVariables3(c, "fmi3SetClock", nvr);
}

// --- dependencies -------------------------------------------------------

LINESIM_FMI_EXPORT fmi3::Status fmi3GetNumberOfVariableDependencies(fmi3::Instance c,
                                                                    fmi3::ValueReference,
                                                                    std::size_t*) {
  return Refuse3(c, "fmi3GetNumberOfVariableDependencies: not provided (see ModelStructure)");
}
enum DependencyKind3 : int {
  kIndependent3,
  kConstant3,
  kFixed3,
  kTunable3,
  kDiscrete3,
  kDependent3
};
LINESIM_FMI_EXPORT fmi3::Status fmi3GetVariableDependencies(fmi3::Instance c, fmi3::ValueReference,
                                                            std::size_t[], fmi3::ValueReference[],
                                                            std::size_t[], DependencyKind3[],
                                                            std::size_t) {
  return Refuse3(c, "fmi3GetVariableDependencies: not provided (see ModelStructure)");
}

// --- state --------------------------------------------------------------

LINESIM_FMI_EXPORT fmi3::Status fmi3GetFMUState(fmi3::Instance c, fmi3::FMUState* state) {
  return S3(fmi2GetFMUstate(c, state));
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetFMUState(fmi3::Instance c, fmi3::FMUState state) {
  return S3(fmi2SetFMUstate(c, state));
}
LINESIM_FMI_EXPORT fmi3::Status fmi3FreeFMUState(fmi3::Instance c, fmi3::FMUState* state) {
  return S3(fmi2FreeFMUstate(c, state));
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SerializedFMUStateSize(fmi3::Instance c, fmi3::FMUState state,
                                                           std::size_t* size) {
  return S3(fmi2SerializedFMUstateSize(c, state, size));
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SerializeFMUState(fmi3::Instance c, fmi3::FMUState state,
                                                      fmi3::Byte bytes[], std::size_t size) {
  return S3(fmi2SerializeFMUstate(c, state, reinterpret_cast<fmi2::Byte*>(bytes), size));
}
LINESIM_FMI_EXPORT fmi3::Status fmi3DeserializeFMUState(fmi3::Instance c, const fmi3::Byte bytes[],
                                                        std::size_t size, fmi3::FMUState* state) {
  return S3(fmi2DeSerializeFMUstate(c, reinterpret_cast<const fmi2::Byte*>(bytes), size, state));
}

// --- not provided -----------------------------------------------------------

LINESIM_FMI_EXPORT fmi3::Status fmi3GetDirectionalDerivative(
    fmi3::Instance c, const fmi3::ValueReference[], std::size_t, const fmi3::ValueReference[],
    std::size_t, const fmi3::Float64[], std::size_t, fmi3::Float64[], std::size_t) {
  return Refuse3(c, "fmi3GetDirectionalDerivative: not provided");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetAdjointDerivative(fmi3::Instance c,
                                                         const fmi3::ValueReference[], std::size_t,
                                                         const fmi3::ValueReference[], std::size_t,
                                                         const fmi3::Float64[], std::size_t,
                                                         fmi3::Float64[], std::size_t) {
  return Refuse3(c, "fmi3GetAdjointDerivative: not provided");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3EnterConfigurationMode(fmi3::Instance c) {
  return Refuse3(c, "fmi3EnterConfigurationMode: the FMU has no structural parameters");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3ExitConfigurationMode(fmi3::Instance c) {
  return Refuse3(c, "fmi3ExitConfigurationMode: the FMU has no structural parameters");
}
enum IntervalQualifier3 : int { kNotYetKnown3, kUnchanged3, kChanged3 };
LINESIM_FMI_EXPORT fmi3::Status fmi3GetIntervalDecimal(fmi3::Instance c,
                                                       const fmi3::ValueReference[], std::size_t,
                                                       fmi3::Float64[], IntervalQualifier3[]) {
  return Refuse3(c, "fmi3GetIntervalDecimal: the FMU has no clocks");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetIntervalFraction(fmi3::Instance c,
                                                        const fmi3::ValueReference[], std::size_t,
                                                        std::uint64_t[], std::uint64_t[],
                                                        IntervalQualifier3[]) {
  return Refuse3(c, "fmi3GetIntervalFraction: the FMU has no clocks");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetShiftDecimal(fmi3::Instance c, const fmi3::ValueReference[],
                                                    std::size_t, fmi3::Float64[]) {
  return Refuse3(c, "fmi3GetShiftDecimal: the FMU has no clocks");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetShiftFraction(fmi3::Instance c, const fmi3::ValueReference[],
                                                     std::size_t, std::uint64_t[],
                                                     std::uint64_t[]) {
  return Refuse3(c, "fmi3GetShiftFraction: the FMU has no clocks");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetIntervalDecimal(fmi3::Instance c,
                                                       const fmi3::ValueReference[], std::size_t,
                                                       const fmi3::Float64[]) {
  return Refuse3(c, "fmi3SetIntervalDecimal: the FMU has no clocks");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetIntervalFraction(fmi3::Instance c,
                                                        const fmi3::ValueReference[], std::size_t,
                                                        const std::uint64_t[],
                                                        const std::uint64_t[]) {
  return Refuse3(c, "fmi3SetIntervalFraction: the FMU has no clocks");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetShiftDecimal(fmi3::Instance c, const fmi3::ValueReference[],
                                                    std::size_t, const fmi3::Float64[]) {
  return Refuse3(c, "fmi3SetShiftDecimal: the FMU has no clocks");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetShiftFraction(fmi3::Instance c, const fmi3::ValueReference[],
                                                     std::size_t, const std::uint64_t[],
                                                     const std::uint64_t[]) {
  return Refuse3(c, "fmi3SetShiftFraction: the FMU has no clocks");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3EvaluateDiscreteStates(fmi3::Instance c) {
  return Refuse3(c, "fmi3EvaluateDiscreteStates: not provided");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3UpdateDiscreteStates(fmi3::Instance c, fmi3::Boolean*,
                                                         fmi3::Boolean*, fmi3::Boolean*,
                                                         fmi3::Boolean*, fmi3::Boolean*,
                                                         fmi3::Float64*) {
  return Refuse3(c, "fmi3UpdateDiscreteStates: event mode is not provided");
}
// Model exchange.
LINESIM_FMI_EXPORT fmi3::Status fmi3EnterContinuousTimeMode(fmi3::Instance c) {
  return Refuse3(c, "fmi3EnterContinuousTimeMode: co-simulation only");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3CompletedIntegratorStep(fmi3::Instance c, fmi3::Boolean,
                                                            fmi3::Boolean*, fmi3::Boolean*) {
  return Refuse3(c, "fmi3CompletedIntegratorStep: co-simulation only");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetTime(fmi3::Instance c, fmi3::Float64) {
  return Refuse3(c, "fmi3SetTime: co-simulation only");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3SetContinuousStates(fmi3::Instance c, const fmi3::Float64[],
                                                        std::size_t) {
  return Refuse3(c, "fmi3SetContinuousStates: co-simulation only");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetContinuousStateDerivatives(fmi3::Instance c, fmi3::Float64[],
                                                                  std::size_t) {
  return Refuse3(c, "fmi3GetContinuousStateDerivatives: co-simulation only");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetEventIndicators(fmi3::Instance c, fmi3::Float64[],
                                                       std::size_t) {
  return Refuse3(c, "fmi3GetEventIndicators: co-simulation only");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetContinuousStates(fmi3::Instance c, fmi3::Float64[],
                                                        std::size_t) {
  return Refuse3(c, "fmi3GetContinuousStates: co-simulation only");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetNominalsOfContinuousStates(fmi3::Instance c, fmi3::Float64[],
                                                                  std::size_t) {
  return Refuse3(c, "fmi3GetNominalsOfContinuousStates: co-simulation only");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetNumberOfEventIndicators(fmi3::Instance c, std::size_t*) {
  return Refuse3(c, "fmi3GetNumberOfEventIndicators: co-simulation only");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetNumberOfContinuousStates(fmi3::Instance c, std::size_t*) {
  return Refuse3(c, "fmi3GetNumberOfContinuousStates: co-simulation only");
}
// Co-simulation.
LINESIM_FMI_EXPORT fmi3::Status fmi3EnterStepMode(fmi3::Instance c) {
  // Only after event mode, which this FMU does not have: step mode follows
  // fmi3ExitInitializationMode directly.
  return Refuse3(c, "fmi3EnterStepMode: event mode is not provided (hasEventMode=false)");
}
LINESIM_FMI_EXPORT fmi3::Status fmi3GetOutputDerivatives(fmi3::Instance c,
                                                         const fmi3::ValueReference[], std::size_t,
                                                         const fmi3::Int32[], fmi3::Float64[],
                                                         std::size_t) {
  return Refuse3(c, "fmi3GetOutputDerivatives: not provided (maxOutputDerivativeOrder=0)");
}

LINESIM_FMI_EXPORT fmi3::Status fmi3DoStep(fmi3::Instance c, fmi3::Float64 t, fmi3::Float64 h,
                                           fmi3::Boolean, fmi3::Boolean* event_handling_needed,
                                           fmi3::Boolean* terminate_simulation,
                                           fmi3::Boolean* early_return,
                                           fmi3::Float64* last_successful_time) {
  const fmi2::Status s = fmi2DoStep(c, t, h, fmi2::kTrue);
  if (event_handling_needed) *event_handling_needed = false;
  if (terminate_simulation) *terminate_simulation = false;
  if (early_return) *early_return = false;
  if (last_successful_time && c)
    *last_successful_time = cosim::NsToSeconds(Of3(c)->last_successful);
  return S3(s);
}

LINESIM_FMI_EXPORT fmi3::Status fmi3ActivateModelPartition(fmi3::Instance c, fmi3::ValueReference,
                                                           fmi3::Float64) {
  return Refuse3(c, "fmi3ActivateModelPartition: co-simulation only");
}

static_assert(
    std::is_same_v<decltype(&fmi3InstantiateCoSimulation), fmi3::InstantiateCoSimulationTYPE>);
static_assert(
    std::is_same_v<decltype(&fmi3EnterInitializationMode), fmi3::EnterInitializationModeTYPE>);
static_assert(std::is_same_v<decltype(&fmi3GetFloat64), fmi3::GetFloat64TYPE>);
static_assert(std::is_same_v<decltype(&fmi3SetFloat64), fmi3::SetFloat64TYPE>);
static_assert(std::is_same_v<decltype(&fmi3GetInt32), fmi3::GetInt32TYPE>);
static_assert(std::is_same_v<decltype(&fmi3SetString), fmi3::SetStringTYPE>);
static_assert(std::is_same_v<decltype(&fmi3DoStep), fmi3::DoStepTYPE>);
static_assert(std::is_same_v<decltype(&fmi3SerializeFMUState), fmi3::SerializeFMUStateTYPE>);
static_assert(std::is_same_v<decltype(&fmi3DeserializeFMUState), fmi3::DeserializeFMUStateTYPE>);
