#pragma once
// The C types and function signatures of the FMI 2.0 and FMI 3.0
// co-simulation interfaces, written from the standards' specifications
// ("Functional Mock-up Interface for Model Exchange and Co-Simulation",
// version 2.0.4, sections 2.1 and 4.2; "Functional Mock-up Interface
// Specification", version 3.0, sections 2.2 and 4.2). Only what an importer
// calls is declared: each function is a pointer type, resolved with dlsym by
// its standard name (the platform binary exports the names unprefixed).

#include <cstddef>
#include <cstdint>

namespace linesim::fmu::fmi2 {

using Component = void*;
using ComponentEnvironment = void*;
using FMUstate = void*;
using ValueReference = unsigned int;
using Real = double;
using Integer = int;
using Boolean = int;
using Char = char;
using String = const Char*;
using Byte = char;

inline constexpr Boolean kTrue = 1;
inline constexpr Boolean kFalse = 0;

enum Status : int { kOK = 0, kWarning = 1, kDiscard = 2, kError = 3, kFatal = 4, kPending = 5 };
enum Type : int { kModelExchange = 0, kCoSimulation = 1 };
enum StatusKind : int {
  kDoStepStatus = 0,
  kPendingStatus = 1,
  kLastSuccessfulTime = 2,
  kTerminated = 3
};

extern "C" {
using CallbackLogger = void (*)(ComponentEnvironment, String instance_name, Status status,
                                String category, String message, ...);
using CallbackAllocateMemory = void* (*)(std::size_t count, std::size_t size);
using CallbackFreeMemory = void (*)(void* object);
using StepFinished = void (*)(ComponentEnvironment, Status);
}

struct CallbackFunctions {
  CallbackLogger logger;
  CallbackAllocateMemory allocateMemory;
  CallbackFreeMemory freeMemory;
  StepFinished stepFinished;
  ComponentEnvironment componentEnvironment;
};

extern "C" {
using GetVersionTYPE = const char* (*)();
using InstantiateTYPE = Component (*)(String instance_name, Type type, String guid,
                                      String resource_location, const CallbackFunctions* functions,
                                      Boolean visible, Boolean logging_on);
using FreeInstanceTYPE = void (*)(Component);
using SetupExperimentTYPE = Status (*)(Component, Boolean tolerance_defined, Real tolerance,
                                       Real start_time, Boolean stop_time_defined, Real stop_time);
using EnterInitializationModeTYPE = Status (*)(Component);
using ExitInitializationModeTYPE = Status (*)(Component);
using TerminateTYPE = Status (*)(Component);
using GetRealTYPE = Status (*)(Component, const ValueReference[], std::size_t, Real[]);
using GetIntegerTYPE = Status (*)(Component, const ValueReference[], std::size_t, Integer[]);
using GetBooleanTYPE = Status (*)(Component, const ValueReference[], std::size_t, Boolean[]);
using GetStringTYPE = Status (*)(Component, const ValueReference[], std::size_t, String[]);
using SetRealTYPE = Status (*)(Component, const ValueReference[], std::size_t, const Real[]);
using SetIntegerTYPE = Status (*)(Component, const ValueReference[], std::size_t, const Integer[]);
using SetBooleanTYPE = Status (*)(Component, const ValueReference[], std::size_t, const Boolean[]);
using SetStringTYPE = Status (*)(Component, const ValueReference[], std::size_t, const String[]);
using GetFMUstateTYPE = Status (*)(Component, FMUstate*);
using SetFMUstateTYPE = Status (*)(Component, FMUstate);
using FreeFMUstateTYPE = Status (*)(Component, FMUstate*);
using SerializedFMUstateSizeTYPE = Status (*)(Component, FMUstate, std::size_t*);
using SerializeFMUstateTYPE = Status (*)(Component, FMUstate, Byte[], std::size_t);
using DeSerializeFMUstateTYPE = Status (*)(Component, const Byte[], std::size_t, FMUstate*);
using DoStepTYPE = Status (*)(Component, Real current_communication_point,
                              Real communication_step_size,
                              Boolean no_set_fmu_state_prior_to_current_point);
using GetRealStatusTYPE = Status (*)(Component, StatusKind, Real*);
using GetBooleanStatusTYPE = Status (*)(Component, StatusKind, Boolean*);
}

}  // namespace linesim::fmu::fmi2

namespace linesim::fmu::fmi3 {

using Instance = void*;
using InstanceEnvironment = void*;
using FMUState = void*;
using ValueReference = std::uint32_t;
using Float64 = double;
using Int32 = std::int32_t;
using Boolean = bool;
using Char = char;
using String = const Char*;
using Byte = std::uint8_t;
using Float32 = float;
using Int8 = std::int8_t;
using UInt8 = std::uint8_t;
using Int16 = std::int16_t;
using UInt16 = std::uint16_t;
using UInt32 = std::uint32_t;
using Int64 = std::int64_t;
using UInt64 = std::uint64_t;

enum Status : int { kOK = 0, kWarning = 1, kDiscard = 2, kError = 3, kFatal = 4 };

extern "C" {
using LogMessageCallback = void (*)(InstanceEnvironment, Status status, String category,
                                    String message);
using IntermediateUpdateCallback = void (*)(InstanceEnvironment, Float64 intermediate_update_time,
                                            Boolean intermediate_variable_set_requested,
                                            Boolean intermediate_variable_get_allowed,
                                            Boolean intermediate_step_finished,
                                            Boolean can_return_early,
                                            Boolean* early_return_requested,
                                            Float64* early_return_time);

using GetVersionTYPE = const char* (*)();
using InstantiateCoSimulationTYPE = Instance (*)(
    String instance_name, String instantiation_token, String resource_path, Boolean visible,
    Boolean logging_on, Boolean event_mode_used, Boolean early_return_allowed,
    const ValueReference required_intermediate_variables[],
    std::size_t n_required_intermediate_variables, InstanceEnvironment instance_environment,
    LogMessageCallback log_message, IntermediateUpdateCallback intermediate_update);
using FreeInstanceTYPE = void (*)(Instance);
using EnterInitializationModeTYPE = Status (*)(Instance, Boolean tolerance_defined,
                                               Float64 tolerance, Float64 start_time,
                                               Boolean stop_time_defined, Float64 stop_time);
using ExitInitializationModeTYPE = Status (*)(Instance);
using TerminateTYPE = Status (*)(Instance);
using GetFloat64TYPE = Status (*)(Instance, const ValueReference[], std::size_t, Float64[],
                                  std::size_t);
using GetInt32TYPE = Status (*)(Instance, const ValueReference[], std::size_t, Int32[],
                                std::size_t);
using GetBooleanTYPE = Status (*)(Instance, const ValueReference[], std::size_t, Boolean[],
                                  std::size_t);
using GetStringTYPE = Status (*)(Instance, const ValueReference[], std::size_t, String[],
                                 std::size_t);
using SetFloat64TYPE = Status (*)(Instance, const ValueReference[], std::size_t, const Float64[],
                                  std::size_t);
using SetInt32TYPE = Status (*)(Instance, const ValueReference[], std::size_t, const Int32[],
                                std::size_t);
using SetBooleanTYPE = Status (*)(Instance, const ValueReference[], std::size_t, const Boolean[],
                                  std::size_t);
using SetStringTYPE = Status (*)(Instance, const ValueReference[], std::size_t, const String[],
                                 std::size_t);
using GetFMUStateTYPE = Status (*)(Instance, FMUState*);
using SetFMUStateTYPE = Status (*)(Instance, FMUState);
using FreeFMUStateTYPE = Status (*)(Instance, FMUState*);
using SerializedFMUStateSizeTYPE = Status (*)(Instance, FMUState, std::size_t*);
using SerializeFMUStateTYPE = Status (*)(Instance, FMUState, Byte[], std::size_t);
using DeserializeFMUStateTYPE = Status (*)(Instance, const Byte[], std::size_t, FMUState*);
using DoStepTYPE = Status (*)(Instance, Float64 current_communication_point,
                              Float64 communication_step_size,
                              Boolean no_set_fmu_state_prior_to_current_point,
                              Boolean* event_handling_needed, Boolean* terminate_simulation,
                              Boolean* early_return, Float64* last_successful_time);
}

// fmi3Get<T> / fmi3Set<T> for the other scalar types (section 2.2.6.2).
template <typename T>
using GetTYPE = Status (*)(Instance, const ValueReference[], std::size_t, T[], std::size_t);
template <typename T>
using SetTYPE = Status (*)(Instance, const ValueReference[], std::size_t, const T[], std::size_t);

}  // namespace linesim::fmu::fmi3
