// Registers the sensors family's encoder and IMU unit types (see
// config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/sensors/belt_encoder_unit.h"
#include "units/sensors/imu_unit.h"
#include "units/sensors/wheel_encoder_unit.h"

namespace linesim::sensors {
namespace {

using config::UnitBuildContext;

std::unique_ptr<cosim::Unit> MakeWheelEncoder(const UnitBuildContext& c) {
  const auto channels = c.reader.Integer(c.parameters, c.path, "channels", 1, 1, 64);
  return std::make_unique<WheelEncoderUnit>(c.name, static_cast<int>(channels));
}

std::unique_ptr<cosim::Unit> MakeImu(const UnitBuildContext& c) {
  return std::make_unique<ImuUnit>(c.name, c.seed);
}

std::unique_ptr<cosim::Unit> MakeBeltEncoder(const UnitBuildContext& c) {
  return std::make_unique<BeltEncoderUnit>(c.name);
}

const config::UnitTypeRegistrar kWheelEncoder(
    {WheelEncoderUnit::kTypeName,
     "incremental quadrature encoders on N joints, read once per step: counts "
     "(floor(angle * cpr / 2 pi)) and the rate a driver computes from them",
     "",
     {{"channels", "number of joints (default 1)"}},
     MakeWheelEncoder});

const config::UnitTypeRegistrar kImu(
    {ImuUnit::kTypeName,
     "strapdown MEMS IMU at a mount pose: angular velocity and specific force (with the "
     "lever-arm terms) plus turn-on bias, bias random walk and white noise, clipped and "
     "quantized",
     "sensors",
     {{"model", "device model file from models/sensors/ (name, e.g. adis16470) or a path "
                "relative to the scenario"}},
     MakeImu});

const config::UnitTypeRegistrar kBeltEncoder(
    {BeltEncoderUnit::kTypeName,
     "the belt's ground-truth speed (paper 1, Sec. V): a free wheel on the belt turning a "
     "quadrature encoder; counts and the speed from their difference over the sample interval",
     "sensors",
     {{"model", "model file from models/sensors/ (name, e.g. belt_ground_truth_encoder) or a "
                "path relative to the scenario"}},
     MakeBeltEncoder});

}  // namespace
}  // namespace linesim::sensors
