#include "models/models_dir.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>

namespace linesim::models {
namespace {

namespace fs = std::filesystem;

// Guards the lookup from a build tree: this test program is in build/, where
// no installed layout is beside it, so the models are the source tree's.
TEST(ModelsDir, FromABuildTreeIsTheSourceTreesFolder) {
  ASSERT_EQ(getenv("LINESIM_MODELS_DIR"), nullptr);
  EXPECT_TRUE(fs::equivalent(ModelsDir(), fs::path(LINESIM_SOURCE_DIR) / "models"));
  EXPECT_TRUE(fs::is_regular_file(fs::path(ModelsDir()) / "robots" / "raw3.yaml"));
}

// Guards the override a sweep's ranks and the tests use.
TEST(ModelsDir, TheEnvironmentComesFirst) {
  setenv("LINESIM_MODELS_DIR", "/some/where", 1);
  const std::string dir = ModelsDir();
  unsetenv("LINESIM_MODELS_DIR");
  EXPECT_EQ(dir, "/some/where");
}

// Guards what an installed linesim finds its files from: the folder of the
// program the code is in (this test program's), and paths relative to it
// only when they exist.
TEST(ModelsDir, InstalledPathsAreRelativeToTheProgram) {
  const fs::path self = fs::read_symlink("/proc/self/exe");
  EXPECT_EQ(fs::path(CodeDir()), self.parent_path());
  EXPECT_TRUE(fs::equivalent(InstalledPath(self.filename().string()), self));
  EXPECT_EQ(InstalledPath("../no_such_folder/models"), "");
}

}  // namespace
}  // namespace linesim::models
