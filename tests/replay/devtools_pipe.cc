#include "tests/replay/devtools_pipe.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace linesim::replay_test {

using Json = nlohmann::json;

DevToolsPipe::DevToolsPipe(const std::string& chromium, const std::string& profile_dir) {
  int to[2], from[2];
  if (pipe2(to, O_CLOEXEC) != 0 || pipe2(from, O_CLOEXEC) != 0) {
    throw std::runtime_error("pipe: " + std::string(std::strerror(errno)));
  }
  const std::string profile = "--user-data-dir=" + profile_dir;
  std::vector<std::string> args = {chromium,
                                   "--headless",
                                   "--no-sandbox",
                                   "--disable-gpu",
                                   "--disable-dev-shm-usage",
                                   "--no-first-run",
                                   "--no-default-browser-check",
                                   "--disable-extensions",
                                   "--remote-debugging-pipe",
                                   profile,
                                   "about:blank"};
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork: " + std::string(std::strerror(errno)));
  if (pid_ == 0) {
    // The child: the pipe ends on fds 3 and 4 (moved out of the way first,
    // dup2 then clears close-on-exec), its own output to /dev/null.
    const int in = fcntl(to[0], F_DUPFD, 10), out = fcntl(from[1], F_DUPFD, 10);
    if (in < 0 || out < 0 || dup2(in, 3) < 0 || dup2(out, 4) < 0) _exit(127);
    const int null = open("/dev/null", O_RDWR);
    if (null >= 0) {
      dup2(null, 0);
      dup2(null, 1);
      dup2(null, 2);
    }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(chromium.c_str(), argv.data());
    _exit(127);
  }
  close(to[0]);
  close(from[1]);
  to_browser_ = to[1];
  from_browser_ = from[0];
}

DevToolsPipe::~DevToolsPipe() {
  try {
    Call("Browser.close", {}, "", 5000);
  } catch (const std::exception&) {
  }
  if (to_browser_ >= 0) close(to_browser_);
  if (from_browser_ >= 0) close(from_browser_);
  if (pid_ > 0) {
    // Up to 10 s to quit, then it is killed (our own child, by its pid).
    for (int i = 0; i < 100; ++i) {
      if (waitpid(pid_, nullptr, WNOHANG) == pid_) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

Json DevToolsPipe::ReadMessage(int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    const std::size_t end = pending_.find('\0');
    if (end != std::string::npos) {
      Json message = Json::parse(pending_.substr(0, end));
      pending_.erase(0, end + 1);
      return message;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                          deadline - std::chrono::steady_clock::now())
                          .count();
    if (left <= 0) throw std::runtime_error("no message from chromium within the time allowed");
    pollfd p{from_browser_, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(left));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    char buf[65536];
    const ssize_t n = read(from_browser_, buf, sizeof buf);
    if (n <= 0) throw std::runtime_error("chromium closed its DevTools pipe (did it start?)");
    pending_.append(buf, static_cast<std::size_t>(n));
  }
}

Json DevToolsPipe::Call(const std::string& method, const Json& params, const std::string& session,
                        int timeout_ms) {
  const int id = next_id_++;
  Json message = {{"id", id}, {"method", method}};
  message["params"] = params.is_null() ? Json::object() : params;
  if (!session.empty()) message["sessionId"] = session;
  const std::string text = message.dump() + std::string(1, '\0');
  for (std::size_t sent = 0; sent < text.size();) {
    const ssize_t n = write(to_browser_, text.data() + sent, text.size() - sent);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error("cannot write to chromium's DevTools pipe");
    sent += static_cast<std::size_t>(n);
  }
  for (;;) {
    Json reply = ReadMessage(timeout_ms);
    if (!reply.contains("id")) {
      events_.push_back(std::move(reply));
      continue;
    }
    if (reply["id"] != id) continue;
    if (reply.contains("error")) {
      throw std::runtime_error(method + ": " + reply["error"].dump());
    }
    return reply["result"];
  }
}

Json DevToolsPipe::WaitFor(const std::string& method, const std::string& session, int timeout_ms) {
  for (const auto& e : events_) {
    if (e.value("method", "") == method && e.value("sessionId", "") == session) return e;
  }
  for (;;) {
    Json message = ReadMessage(timeout_ms);
    if (message.contains("id")) continue;
    events_.push_back(message);
    if (message.value("method", "") == method && message.value("sessionId", "") == session) {
      return message;
    }
  }
}

std::string DevToolsPipe::OpenPage() {
  const Json target = Call("Target.createTarget", {{"url", "about:blank"}});
  const Json attached = Call("Target.attachToTarget",
                             {{"targetId", target["targetId"]}, {"flatten", true}});
  return attached["sessionId"].get<std::string>();
}

Json DevToolsPipe::Evaluate(const std::string& session, const std::string& expression) {
  const Json r = Call("Runtime.evaluate",
                      {{"expression", expression}, {"returnByValue", true}, {"awaitPromise", true}},
                      session);
  if (r.contains("exceptionDetails")) {
    throw std::runtime_error("the page threw: " + r["exceptionDetails"].dump());
  }
  return r["result"].value("value", Json());
}

}  // namespace linesim::replay_test
