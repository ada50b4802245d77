#pragma once

// FMU archives made at run time with libzip, for the tests of malformed and
// hostile FMUs.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <zip.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace linesim::fmu::test {

struct Entry {
  std::string name;
  std::string content;
  bool symlink = false;
  std::uint32_t unix_mode = 0;  // when not 0: the entry's Unix external attributes (mode << 16)
};

inline void MakeZip(const std::string& file, const std::vector<Entry>& entries) {
  int error = 0;
  zip_t* z = zip_open(file.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  ASSERT_NE(z, nullptr);
  for (const auto& e : entries) {
    zip_source_t* src = zip_source_buffer(z, e.content.data(), e.content.size(), 0);
    ASSERT_NE(src, nullptr);
    const zip_int64_t index = zip_file_add(z, e.name.c_str(), src, ZIP_FL_ENC_UTF_8);
    ASSERT_GE(index, 0) << e.name << ": " << zip_strerror(z);
    if (e.unix_mode != 0) {
      ASSERT_EQ(zip_file_set_external_attributes(z, static_cast<zip_uint64_t>(index), 0,
                                                 ZIP_OPSYS_UNIX, e.unix_mode << 16),
                0);
    }
    if (e.symlink) {
      const zip_uint32_t mode = S_IFLNK | 0777;
      ASSERT_EQ(zip_file_set_external_attributes(z, static_cast<zip_uint64_t>(index), 0,
                                                 ZIP_OPSYS_UNIX, mode << 16),
                0);
    }
  }
  ASSERT_EQ(zip_close(z), 0);
}

inline std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace linesim::fmu::test
