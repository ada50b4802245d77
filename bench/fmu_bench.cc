// The fmu unit's overhead per step beyond the FMU's own doStep, on the
// feedthrough2 test FMU (tests/units/fmu/fmus/feedthrough2.c: 10 scalars,
// 5 inputs and 5 outputs of every FMI 2.0 type, and a tunable parameter).
//
//   BM_FmuBareDoStep     fmi2DoStep alone, called through dlsym'd pointers
//   BM_FmuBareExchange   what any master must call per step: set the 5
//                        inputs (4 calls), fmi2DoStep, get the 5 outputs
//                        (4 calls)
//   BM_FmuUnitDoStep     FmuUnit::DoStep: the same calls plus the unit's
//                        checks (finite inputs, step size, tunables) and
//                        the copies between the table and the FMI buffers
// The wrapper's overhead = BM_FmuUnitDoStep - BM_FmuBareExchange (the FMU's
// own work), or - BM_FmuBareDoStep for everything beyond doStep.

#include <benchmark/benchmark.h>
#include <dlfcn.h>

#include <filesystem>
#include <string>

#include "units/fmu/fmi_api.h"
#include "units/fmu/fmu_unit.h"

namespace {

using namespace linesim::fmu;

#ifdef LINESIM_TEST_FMU_DIR
const std::string kDir = LINESIM_TEST_FMU_DIR;
#else
const std::string kDir;
#endif

constexpr linesim::cosim::TimeNs kStep = 1'000'000;

struct Bare {
  void* handle = nullptr;
  fmi2::Component c = nullptr;
  fmi2::CallbackFunctions cb{};
  fmi2::DoStepTYPE DoStep = nullptr;
  fmi2::SetRealTYPE SetReal = nullptr;
  fmi2::SetIntegerTYPE SetInteger = nullptr;
  fmi2::SetBooleanTYPE SetBoolean = nullptr;
  fmi2::SetStringTYPE SetString = nullptr;
  fmi2::GetRealTYPE GetReal = nullptr;
  fmi2::GetIntegerTYPE GetInteger = nullptr;
  fmi2::GetBooleanTYPE GetBoolean = nullptr;
  fmi2::GetStringTYPE GetString = nullptr;
  fmi2::FreeInstanceTYPE FreeInstance = nullptr;

  bool Open() {
    const std::string so = kDir + "/fmu_build/feedthrough2/lib/feedthrough2.so";
    handle = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) return false;
    const auto get = [&](auto& f, const char* name) {
      f = reinterpret_cast<std::remove_reference_t<decltype(f)>>(dlsym(handle, name));
    };
    fmi2::InstantiateTYPE Instantiate;
    fmi2::SetupExperimentTYPE Setup;
    fmi2::EnterInitializationModeTYPE Enter;
    fmi2::ExitInitializationModeTYPE Exit;
    get(Instantiate, "fmi2Instantiate");
    get(Setup, "fmi2SetupExperiment");
    get(Enter, "fmi2EnterInitializationMode");
    get(Exit, "fmi2ExitInitializationMode");
    get(FreeInstance, "fmi2FreeInstance");
    get(DoStep, "fmi2DoStep");
    get(SetReal, "fmi2SetReal");
    get(SetInteger, "fmi2SetInteger");
    get(SetBoolean, "fmi2SetBoolean");
    get(SetString, "fmi2SetString");
    get(GetReal, "fmi2GetReal");
    get(GetInteger, "fmi2GetInteger");
    get(GetBoolean, "fmi2GetBoolean");
    get(GetString, "fmi2GetString");
    cb.allocateMemory = [](std::size_t n, std::size_t s) { return std::calloc(n, s); };
    cb.freeMemory = [](void* p) { std::free(p); };
    c = Instantiate("bare", fmi2::kCoSimulation, "{linesim-test-feedthrough-2}", "", &cb,
                    fmi2::kFalse, fmi2::kFalse);
    if (!c) return false;
    Setup(c, fmi2::kFalse, 0, 0, fmi2::kFalse, 0);
    Enter(c);
    Exit(c);
    return true;
  }
  ~Bare() {
    if (c) FreeInstance(c);
    if (handle) dlclose(handle);
  }
};

void BM_FmuBareDoStep(benchmark::State& state) {
  Bare b;
  if (!b.Open()) {
    state.SkipWithError("feedthrough2 test FMU not built (configure with tests on)");
    return;
  }
  double t = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(b.DoStep(b.c, t, 0.001, fmi2::kTrue));
    t += 0.001;
  }
}
BENCHMARK(BM_FmuBareDoStep);

void BM_FmuBareExchange(benchmark::State& state) {
  Bare b;
  if (!b.Open()) {
    state.SkipWithError("feedthrough2 test FMU not built (configure with tests on)");
    return;
  }
  const fmi2::ValueReference in_real[] = {0, 1}, out_real[] = {3, 4}, in_one[] = {0},
                             out_one[] = {1};
  double reals[2] = {0.5, 1.5}, real_out[2];
  int integer = 3, boolean = 1, integer_out = 0, boolean_out = 0;
  fmi2::String text = "start";
  fmi2::String text_out = nullptr;
  double t = 0;
  for (auto _ : state) {
    b.SetReal(b.c, in_real, 2, reals);
    b.SetInteger(b.c, in_one, 1, &integer);
    b.SetBoolean(b.c, in_one, 1, &boolean);
    b.SetString(b.c, in_one, 1, &text);
    b.DoStep(b.c, t, 0.001, fmi2::kTrue);
    b.GetReal(b.c, out_real, 2, real_out);
    b.GetInteger(b.c, out_one, 1, &integer_out);
    b.GetBoolean(b.c, out_one, 1, &boolean_out);
    b.GetString(b.c, out_one, 1, &text_out);
    benchmark::DoNotOptimize(real_out);
    benchmark::DoNotOptimize(text_out);
    t += 0.001;
  }
}
BENCHMARK(BM_FmuBareExchange);

void UnitBench(benchmark::State& state) {
  const std::string file = kDir + "/feedthrough2.fmu";
  if (kDir.empty() || !std::filesystem::exists(file)) {
    state.SkipWithError("feedthrough2 test FMU not built (configure with tests on)");
    return;
  }
  FmuUnit unit("f", file);
  unit.Setup(0, INT64_MAX / 2);
  unit.Initialize();
  unit.variables().Lock();
  const auto in_a = *unit.variables().Find("in_a");
  std::int64_t n = 0;
  for (auto _ : state) {
    unit.variables().SetReal(in_a, static_cast<double>(n & 7));
    if (unit.DoStep(n * kStep, kStep) != linesim::cosim::StepResult::kOk) {
      state.SkipWithError(unit.last_error().c_str());
      break;
    }
    ++n;
  }
}
void BM_FmuUnitDoStep(benchmark::State& state) { UnitBench(state); }
BENCHMARK(BM_FmuUnitDoStep);

}  // namespace

// --- export-fmu: the exported dc_motor FMU against the native unit --------
//
//   BM_ExportedMotor/native    the native dc_motor unit (maxon RE 40 148877,
//                              models/motors/), DoStep of 1 ms
//   BM_ExportedMotor/fmu       the same unit exported with `export-fmu` and
//                              run through the fmu unit (FmuUnit::DoStep:
//                              fmi2SetReal, fmi2DoStep, fmi2GetReal into the
//                              exported runtime, which steps its own dc_motor)
// Arg: 0 = constant 24 V (CVODE continues), 1 = the voltage changes every
// 10th step (CVODE restarts then). The difference is the export's and
// import's cost per step together. With one motor the FMU is FMI 2.0.

#include <unistd.h>

#include <fstream>
#include <memory>

#include "fmu_export/exporter.h"
#include "loader/scenario.h"

namespace {

struct ExportedMotor {
  std::filesystem::path folder;
  std::unique_ptr<linesim::loader::Scenario> native;
  std::unique_ptr<FmuUnit> fmu;

  ExportedMotor() {
    folder = std::filesystem::temp_directory_path() /
             ("linesim-bench-export-" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder);
    const std::string fmu_file = (folder / "motor.fmu").string();
    linesim::fmu_export::ExportFmu({"dc_motor", {"model=maxon_re40_148877"}, fmu_file, "", "", 0});
    const std::string yaml = (folder / "native.yaml").string();
    std::ofstream(yaml) << "duration_s: 1\nunits:\n  motor:\n    type: dc_motor\n"
                           "    parameters: {model: maxon_re40_148877}\n";
    native = std::make_unique<linesim::loader::Scenario>(linesim::loader::LoadScenario(yaml));
    fmu = std::make_unique<FmuUnit>("motor_fmu", fmu_file);
  }
  ~ExportedMotor() {
    fmu.reset();
    std::filesystem::remove_all(folder);
  }
};

void BM_ExportedMotor(benchmark::State& state, bool through_fmu) {
  std::unique_ptr<ExportedMotor> m;
  try {
    m = std::make_unique<ExportedMotor>();
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  linesim::cosim::Unit& u = through_fmu ? static_cast<linesim::cosim::Unit&>(*m->fmu)
                                        : m->native->system->unit(0);
  u.Setup(0, INT64_MAX / 2);
  u.Initialize();
  u.variables().Lock();
  const auto voltage = *u.variables().Find("voltage");
  const bool is_array = u.variables().info(voltage).type == linesim::cosim::VarType::kRealArray;
  const bool changing = state.range(0) != 0;
  std::int64_t n = 0;
  for (auto _ : state) {
    const double v = changing && (n / 10) % 2 == 1 ? 12.0 : 24.0;
    if (is_array) {
      u.variables().SetRealElement(voltage, 0, v);
    } else {
      u.variables().SetReal(voltage, v);
    }
    if (u.DoStep(n * kStep, kStep) != linesim::cosim::StepResult::kOk) {
      state.SkipWithError(u.last_error().c_str());
      break;
    }
    ++n;
  }
}
BENCHMARK_CAPTURE(BM_ExportedMotor, native, false)->Arg(0)->Arg(1);
BENCHMARK_CAPTURE(BM_ExportedMotor, fmu, true)->Arg(0)->Arg(1);

}  // namespace
