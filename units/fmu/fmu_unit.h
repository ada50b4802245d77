#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "cosim/unit.h"
#include "units/fmu/fmi_api.h"
#include "units/fmu/model_description.h"

namespace linesim::fmu {

class FmuBinary;
class TempFolder;

/// What became of each FMI variable in the unit's table.
struct MappedVariable {
  std::string fmi_name;  // as in modelDescription.xml ("motor.R")
  std::string name;      // in the VariableTable ("motor_R")
  std::uint32_t value_reference = 0;
  bool mapped = true;  // false: left out (a non-Real local, the independent time)
};

/// An FMI 2.0 or FMI 3.0 co-simulation FMU as a linesim unit (type `fmu`).
///
/// The constructor unpacks the archive into a private temporary folder
/// (see Unpack: no entry may land outside it), reads modelDescription.xml,
/// dlopens binaries/linux64/ (FMI 2.0) or binaries/x86_64-linux/ (FMI 3.0)
/// <modelIdentifier>.so and resolves every function the unit calls, and
/// declares the FMU's variables: parameters (fixed, tunable, structural as
/// constant), inputs, outputs, Float64 locals and calculated parameters as
/// locals. Outputs declare no direct dependency: in step mode the standard
/// allows no fmi*Get after an fmi*Set before the next doStep (FMI 2.0.4
/// section 4.2.4, FMI 3.0.2 Step Mode), so a co-simulation FMU's outputs
/// are doStep's; ModelStructure's dependencies, which hold in
/// initialization mode, are named in the description. Names that are no
/// linesim identifier are written with '_' ("motor.R" -> "motor_R"); the
/// description keeps the FMI name and value reference.
///
/// Setup instantiates (the log goes to messages()); the first Initialize
/// sets parameters and inputs and enters initialization mode, and every
/// Initialize (and UpdateOutputs) sets inputs and reads outputs in it; the
/// first DoStep exits it, and from then on UpdateOutputs calls nothing. DoStep(t, dt) calls doStep
/// at t and dt as the master gives them (integer nanoseconds, so every communication point is start
/// + k h exactly). fmi2Discard / fmi3Discard give StepResult::kDiscard; an FMI 3.0 early return is
/// continued from lastSuccessfulTime to t + dt; a terminate request (fmi2Discard with
/// fmi2Terminated, fmi3DoStep's terminateSimulation) reads the outputs and asks the master to end
/// the run there (Unit::stop_request). SaveState / RestoreState use get/setFMUstate (serialized
/// into the UnitState when canSerializeFMUstate), and throw naming the capability when the FMU has
/// neither.
class FmuUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "fmu";

  /// Throws FmuError naming the file and what is wrong.
  FmuUnit(std::string name, const std::string& fmu_file);
  /// A unit with no FMU (`linesim inspect fmu`): one placeholder local, and
  /// CheckParameters reports that `path` must be set.
  explicit FmuUnit(std::string name);
  ~FmuUnit() override;

  const ModelDescription& description() const { return description_; }
  const std::string& file() const { return file_; }
  const std::vector<MappedVariable>& mapping() const { return mapping_; }
  /// The FMU's log (logger / logMessage callbacks), oldest first, as
  /// "status [category] message"; the last kMaxMessages are kept. The FMU is
  /// instantiated with loggingOn = false (no debug logging, which would
  /// cost every step): it still reports warnings and errors. linesim has no
  /// channel for a unit's messages during a run: they stay here, and the
  /// ones logged during a failed call are added to its error.
  const std::deque<std::string>& messages() const { return messages_; }
  /// How many messages the FMU logged in all (the oldest beyond
  /// kMaxMessages are dropped).
  std::size_t message_count() const { return message_count_; }
  static constexpr std::size_t kMaxMessages = 1000;
  /// FMI 3.0 early returns the unit continued (see DoStep), since loading.
  std::size_t early_returns() const { return early_returns_; }
  /// The most early returns within one communication step: each must
  /// advance the FMU's time; beyond this many the step fails (an event
  /// that never ends would otherwise hang the run).
  static constexpr std::size_t kMaxEarlyReturns = 100'000;

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  void UpdateOutputs() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;
  void Terminate() override;

  // For the logging callbacks.
  void Log(int status, const char* category, const char* message);

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  // kError: a call returned Error (only FreeInstance or a state restore
  // may follow); kBroken: Fatal (nothing may follow but forgetting it).
  enum class Mode : std::int64_t {
    kNone = 0,
    kInstantiated,
    kInitialization,
    kStep,
    kTerminated,
    kBroken,
    kError
  };
  // One direction of one type: the FMI value references and the first slot
  // of its contiguous storage.
  struct Group {
    std::vector<std::uint32_t> vrs;
    std::size_t first = 0;
  };
  struct ArraySlot {
    std::uint32_t vr;
    std::size_t index;  // into arrays_
  };
  // A group of one of the FMI 3.0 types beyond Float64 / Int32 / Boolean /
  // String (Float32 in reals_, the other integer types in integers_).
  struct TypedGroup {
    FmiType type;
    Group group;
  };
  struct Groups {
    Group real, integer, boolean, string;
    std::vector<ArraySlot> arrays;
    std::vector<TypedGroup> extras;
  };
  // Fixed parameters, tunable parameters, inputs, outputs, locals (and
  // calculated parameters). Structural parameters are declared read-only
  // and belong to no group.
  enum Direction { kParameters = 0, kTunables, kInputs, kOutputs, kLocals, kDirections };

  void DeclareVariables();
  void FreeInstance();
  // Each returns false after recording why (Fail) when a call fails.
  void SetGroups(const Groups& g, const char* phase);
  void GetGroups(const Groups& g, const char* phase);
  void SetExtra(const TypedGroup& x, const char* phase);
  void GetExtra(const TypedGroup& x, const char* phase);
  /// Throws UnitError when integer slot `slot` holds `x` outside its FMI
  /// type's range or, for an enumeration, no item.
  void CheckInteger(std::size_t slot, std::int64_t x, const char* phase) const;
  void SetTunables();
  void RememberTunables();
  /// Status of an FMI call: throws UnitError for error / fatal (and for
  /// discard outside doStep); `call` names the function.
  void Check(int status, const char* call, const char* phase);
  std::string Describe(const char* call, int status) const;
  std::string RecentMessages(std::size_t since) const;

  std::string file_;
  ModelDescription description_;
  std::unique_ptr<TempFolder> folder_;
  std::unique_ptr<FmuBinary> binary_;
  std::vector<MappedVariable> mapping_;

  // Storage the table binds to, one block per type; each direction's
  // variables are contiguous, so one FMI call moves a whole group.
  std::unique_ptr<double[]> reals_;
  std::unique_ptr<std::int64_t[]> integers_;
  std::unique_ptr<bool[]> booleans_;
  std::vector<std::string> strings_;
  std::vector<std::vector<double>> arrays_;
  Groups groups_[kDirections];
  // Conversion buffers (FMI 2.0 Integer and Boolean are int; strings are
  // passed as pointers), sized once.
  std::vector<int> int_buffer_;
  // Conversion to the other FMI 3.0 types (a char array provides storage
  // for any of them), and per integer slot its variable (for its range).
  std::unique_ptr<unsigned char[]> conversion_;
  std::vector<std::size_t> integer_variable_;
  std::vector<double> sent_extra_reals_;
  std::vector<std::int64_t> sent_extra_integers_;
  std::vector<const char*> string_buffer_;
  // Tunable parameters: the values last given to the FMU.
  std::vector<double> sent_reals_;
  std::vector<std::int64_t> sent_integers_;
  std::vector<char> sent_booleans_;
  std::vector<std::string> sent_strings_;
  bool has_tunables_ = false;

  void* instance_ = nullptr;
  Mode mode_ = Mode::kNone;
  cosim::TimeNs start_ = 0;
  cosim::TimeNs stop_ = 0;
  cosim::TimeNs first_dt_ =
      0;  // the first communication step (variable steps refused when the FMU cannot)
  // States kept by the FMU when it cannot serialize them: a saved
  // UnitState names one by index (and this unit by id_).
  mutable std::vector<void*> kept_states_;
  std::int64_t id_ = 0;
  std::size_t early_returns_ = 0;

  std::deque<std::string> messages_;
  std::size_t message_count_ = 0;  // all ever logged
  std::size_t call_messages_ = 0;  // message_count_ when the current call began
  fmi2::CallbackFunctions callbacks2_{};
  double placeholder_ = 0;
};

}  // namespace linesim::fmu
