#pragma once

// A headless Chromium driven over the DevTools protocol on a pipe
// (--remote-debugging-pipe: commands on the browser's fd 3, replies and
// events on its fd 4, each message a JSON text ended by a NUL byte). No
// WebSocket and no library: the test talks to Debian's chromium directly.

#include <sys/types.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace linesim::replay_test {

class DevToolsPipe {
 public:
  /// Starts `chromium` headless (as root it needs --no-sandbox) with a
  /// fresh profile in `profile_dir`. Throws std::runtime_error when it cannot.
  DevToolsPipe(const std::string& chromium, const std::string& profile_dir);
  ~DevToolsPipe();
  DevToolsPipe(const DevToolsPipe&) = delete;
  DevToolsPipe& operator=(const DevToolsPipe&) = delete;

  /// Sends a command (to the browser, or to a page's session) and returns
  /// its result; throws with the protocol's error message, or after
  /// `timeout_ms` without a reply. Events arriving meanwhile are kept.
  nlohmann::json Call(const std::string& method, const nlohmann::json& params = {},
                      const std::string& session = "", int timeout_ms = 30000);
  /// Waits for the event `method` (of `session`) and returns it.
  nlohmann::json WaitFor(const std::string& method, const std::string& session,
                         int timeout_ms = 30000);
  /// Every event received so far.
  const std::vector<nlohmann::json>& events() const { return events_; }

  /// A new page's session id (Target.createTarget + attachToTarget, flat).
  std::string OpenPage();
  /// Evaluates `expression` in the page (awaiting a promise) and returns
  /// its value; throws with the page's exception text.
  nlohmann::json Evaluate(const std::string& session, const std::string& expression);

 private:
  nlohmann::json ReadMessage(int timeout_ms);
  pid_t pid_ = -1;
  int to_browser_ = -1, from_browser_ = -1;
  int next_id_ = 1;
  std::string pending_;
  std::vector<nlohmann::json> events_;
};

}  // namespace linesim::replay_test
