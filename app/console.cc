#include "app/console.h"

#include <filesystem>
#include <iostream>
#include <system_error>

namespace linesim::app {

void PrintIssues(const config::ScenarioError& e, const std::string& what, std::ostream& out) {
  out << "linesim: the " << what << " is refused (" << e.issues().size()
      << (e.issues().size() == 1 ? " problem" : " problems") << "):\n";
  for (const auto& i : e.issues()) out << "  " << i.ToString() << "\n";
}

bool CreateOutputFolder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!ec && std::filesystem::is_directory(dir, ec)) return true;
  std::cerr << "linesim: cannot create the output folder " << dir << ": "
            << (ec ? ec.message() : "a file of that name exists") << "\n";
  return false;
}

}  // namespace linesim::app
