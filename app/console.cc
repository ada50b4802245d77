#include "app/console.h"

#include <unistd.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <system_error>

#include "units/fmu/fmu_archive.h"

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

namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "used from a signal handler");
std::atomic<const char*> g_stop_message{""};

extern "C" void OnStopSignal(int sig) {
  if (g_stop.exchange(true)) {
    // A second signal ends the process at once: the unpacked FMUs go first.
    fmu::RemoveLiveTempFolders();
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    return;
  }
  const char* text = g_stop_message.load();
  [[maybe_unused]] const auto n = write(STDERR_FILENO, text, std::strlen(text));
}

}  // namespace

std::atomic<bool>& InstallStopSignals(const char* message) {
  g_stop_message.store(message);
  std::signal(SIGINT, OnStopSignal);
  std::signal(SIGTERM, OnStopSignal);
  return g_stop;
}

}  // namespace linesim::app
