// The shared whole-file helpers: a reader never sees half a file, and a
// failed write leaves no temporary behind and names the file.
#include "cosim/files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace linesim::cosim {
namespace {

namespace fs = std::filesystem;

fs::path Fresh(const std::string& name) {
  const fs::path p = fs::path(::testing::TempDir()) / ("files_" + std::to_string(getpid()) + name);
  fs::remove_all(p);
  return p;
}

TEST(Files, WritesAtomicallyAndReadsBack) {
  const fs::path p = Fresh("a.txt");
  WriteFileAtomically(p.string(), "first\n");
  WriteFileAtomically(p.string(), std::string("second\0with a zero\n", 19));
  EXPECT_EQ(ReadWholeFile(p.string()), std::string("second\0with a zero\n", 19));
  EXPECT_FALSE(fs::exists(p.string() + ".tmp"));
  EXPECT_FALSE(ReadWholeFile(Fresh("missing.txt").string()).has_value());
}

TEST(Files, AFailedWriteNamesTheFileAndLeavesNoTemporary) {
  // The temporary cannot be made: its folder does not exist.
  const fs::path nowhere = Fresh("no_such_folder") / "x.json";
  try {
    WriteFileAtomically(nowhere.string(), "x");
    FAIL() << "wrote into a missing folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(nowhere.string()), std::string::npos) << e.what();
  }
  // The temporary is written but cannot replace a folder of the same name.
  const fs::path folder = Fresh("taken");
  fs::create_directories(folder / "inside");
  EXPECT_THROW(WriteFileAtomically(folder.string(), "x"), std::runtime_error);
  EXPECT_FALSE(fs::exists(folder.string() + ".tmp"));
  EXPECT_TRUE(fs::is_directory(folder / "inside"));
}

}  // namespace
}  // namespace linesim::cosim
