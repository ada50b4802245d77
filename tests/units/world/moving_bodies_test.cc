// The fleet's bodies gathered into one array.
#include "units/world/moving_bodies_unit.h"

#include <gtest/gtest.h>

#include <vector>

#include "tests/units/test_helpers.h"

namespace linesim::world {
namespace {

using test_helpers::Get;
using test_helpers::SetArray;

// Guards against a gather that lags or loses a body: the output is the
// input at the same communication point (feedthrough, declared so that the
// master orders the readers after it), before and after a step; a body
// never given is absent (length 0).
TEST(MovingBodies, OutputIsTheInputNow) {
  MovingBodiesUnit u("bodies", 2);
  u.Initialize();
  EXPECT_EQ(Get(u, "bodies"), std::vector<double>(20, 0.0));
  std::vector<double> in(20, 0.0);
  for (std::size_t k = 0; k < 10; ++k) in[k] = 1.0 + static_cast<double>(k);
  SetArray(u, "bodies_in", in);
  u.UpdateOutputs();
  EXPECT_EQ(Get(u, "bodies"), in);
  in[0] = 5.0;
  SetArray(u, "bodies_in", in);
  ASSERT_EQ(u.DoStep(0, 5'000'000), cosim::StepResult::kOk);
  EXPECT_EQ(Get(u, "bodies"), in);
  const auto& v = u.variables();
  EXPECT_FALSE(v.info(*v.Find("bodies")).depends_on.empty());
}

}  // namespace
}  // namespace linesim::world
