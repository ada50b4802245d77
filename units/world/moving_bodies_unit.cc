#include "units/world/moving_bodies_unit.h"

#include "models/moving_solids.h"

namespace linesim::world {

MovingBodiesUnit::MovingBodiesUnit(std::string name, int count)
    : cosim::Unit(kTypeName, std::move(name)) {
  if (count < 1) throw cosim::UnitError(Where() + ": needs at least one body");
  // Absent until connected (length 0).
  in_.assign(models::MovingBox::kValues * static_cast<std::size_t>(count), 0.0);
  out_ = in_;
  auto& v = variables();
  v.Input("bodies_in", "m, rad, m/s, rad/s", &in_,
          "each body (a chassis' body_box: [x, y, yaw, vx, vy, yaw_rate, length, width, "
          "z_bottom, z_top] in map), one after another");
  v.Output("bodies", "m, rad, m/s, rad/s", &out_, "the same, for the units that meet them",
           {"bodies_in"});
}

cosim::StepResult MovingBodiesUnit::DoStep(cosim::TimeNs t, cosim::TimeNs) {
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  UpdateOutputs();
  return cosim::StepResult::kOk;
}

}  // namespace linesim::world
