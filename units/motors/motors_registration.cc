// Registers the motors family's unit types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/motors/dc_motor_unit.h"

namespace linesim::motors {
namespace {

using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakeDcMotor(const UnitBuildContext& c) {
  const auto count = c.reader.Integer(c.parameters, c.path, "count", 1, 1, 64);
  const std::string mode =
      c.reader.String(c.parameters, c.path, "mode", "full", {"full", "current_only"});
  return std::make_unique<motors::DcMotorUnit>(
      c.name, static_cast<int>(count),
      mode == "full" ? motors::MotorMode::kFull : motors::MotorMode::kCurrentOnly);
}

const config::UnitTypeRegistrar kDcMotor(
    {motors::DcMotorUnit::kTypeName,
     "brushed DC motors with gearbox, integrated together in SUNDIALS CVODE (BDF)",
     "motors",
     {{"count", "number of motors in this unit (default 1)"},
      {"mode",
       "full: current and rotor speed are states, load torque is an input; current_only: "
       "the shaft speed is an input from the physics (default full)"},
      {"model", "model file from models/motors/ (name) or a path relative to the scenario"}},
     MakeDcMotor});

}  // namespace
}  // namespace linesim::motors
