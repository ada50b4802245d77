#include "fuzz/fuzz_support.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace linesim::fuzz {

const std::string& TempDir() {
  static const std::string dir = [] {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base != nullptr && *base != '\0' ? base : "/tmp") +
                          "/linesim_fuzz_XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("linesim fuzz: mkdtemp");
      std::abort();
    }
    return pattern;
  }();
  return dir;
}

void WriteFile(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::perror(("linesim fuzz: cannot write " + path).c_str());
    std::abort();
  }
}

std::vector<std::string> SetArgs(const std::string& text, std::size_t max) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (out.size() < max && std::getline(in, line)) {
    if (line.rfind("#set ", 0) == 0) out.push_back(line.substr(5));
  }
  return out;
}

}  // namespace linesim::fuzz
