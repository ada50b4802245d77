#include <gtest/gtest.h>

#include <string>

#include "loader/scenario.h"
#include "scenario_test.h"

// The scene and line concern (loader/assembly/scene_and_line.cc): line.belts
// merged item by item onto the scene's belts.
namespace linesim::loader {
namespace {

using testing::Has;
using testing::Issues;

const std::string kHold = LINESIM_SOURCE_DIR "/scenarios/hold_on_belt.yaml";

// Guards issue 24's silent result: an empty line.belts (here from --set)
// merged item by item left the scene's belts as they were and the run went
// on with exit 0. It is refused at line.belts (only there), as the README
// promises for every empty list.
TEST(SceneAndLineAssembly, EmptyLineBeltsIsRefused) {
  const std::string e = Issues(kHold, {"line.belts=[]"});
  EXPECT_TRUE(Has(e, "line.belts (set on the command line): an empty list removes nothing"))
      << e;
  // Once, at the user's key: not echoed at the scene's belts.
  EXPECT_FALSE(Has(e, "scene.belts")) << e;
  EXPECT_EQ(Issues(kHold, {"line.belts.0.speed_mps=0.15"}), "(no error)");
}

}  // namespace
}  // namespace linesim::loader
