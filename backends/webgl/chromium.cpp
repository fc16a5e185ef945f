#include "backends/webgl/chromium.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace flatmarch::webgl {

using nlohmann::json;

namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string errno_text(const char* what) {
  return std::string(what) + ": " + std::strerror(errno);
}

// A descriptor numbered 10 or more, close-on-exec: dup2 onto 3 or 4 then always makes a copy
// whose close-on-exec flag is clear (dup2 of a descriptor onto itself would keep the flag).
int high_fd(int fd) {
  const int high = fcntl(fd, F_DUPFD_CLOEXEC, 10);
  close(fd);
  if (high < 0) throw std::runtime_error(errno_text("Chromium: fcntl"));
  return high;
}

// The last lines of the browser's log, for an error message.
std::string log_tail(const std::string& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  if (text.size() > 600) text = "..." + text.substr(text.size() - 600);
  return text.empty() ? "" : "; its log ends: " + text;
}

}  // namespace

std::optional<std::string> find_chromium() {
  if (const char* env = std::getenv("FLATMARCH_CHROMIUM"); env && *env) return std::string(env);
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
    std::stringstream s(dirs);
    for (std::string dir; std::getline(s, dir, ':');) {
      const std::string file = (dir.empty() ? "." : dir) + "/" + name;
      if (access(file.c_str(), X_OK) == 0) return file;
    }
  }
  return std::nullopt;
}

std::vector<std::string> device_flags(const std::string& device) {
  if (device.empty()) return {"--enable-unsafe-swiftshader"};
  if (device == "swiftshader" || device == "cpu")
    return {"--use-angle=swiftshader", "--enable-unsafe-swiftshader"};
  if (device == "gpu") return {"--use-angle=gl", "--ignore-gpu-blocklist", "--enable-gpu"};
  throw std::invalid_argument(
      "the webgl backend's --device is one of gpu, swiftshader (or cpu), or empty for "
      "Chromium's choice; not " +
      device);
}

Chromium::Chromium(const std::string& executable, const std::vector<std::string>& flags,
                   double timeout_s) {
  int to[2], from[2];
  if (pipe2(to, O_CLOEXEC) != 0) throw std::runtime_error(errno_text("Chromium: pipe"));
  if (pipe2(from, O_CLOEXEC) != 0) {
    close(to[0]);
    close(to[1]);
    throw std::runtime_error(errno_text("Chromium: pipe"));
  }
  const int child_in = high_fd(to[0]), child_out = high_fd(from[1]);
  to_browser_ = to[1];
  from_browser_ = from[0];

  char log_name[] = "/tmp/flatmarch-chromium-XXXXXX";
  const int log_fd = mkstemp(log_name);
  log_ = log_fd >= 0 ? log_name : "";

  std::vector<std::string> args = {
      executable, "--headless", "--no-sandbox", "--remote-debugging-pipe", "--no-first-run",
      "--no-default-browser-check", "--disable-extensions", "--mute-audio", "--hide-scrollbars",
      // Pages are files; nothing is fetched.
      "--host-resolver-rules=MAP * ~NOTFOUND"};
  args.insert(args.end(), flags.begin(), flags.end());
  args.push_back("about:blank");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  if (log_fd >= 0) {
    posix_spawn_file_actions_adddup2(&actions, log_fd, 1);
    posix_spawn_file_actions_adddup2(&actions, log_fd, 2);
  } else {
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  }
  posix_spawn_file_actions_adddup2(&actions, child_in, 3);
  posix_spawn_file_actions_adddup2(&actions, child_out, 4);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  // Its own process group: stop() ends the browser's helper processes with it.
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  // The browser runs outside a supervised worker's address-space limit (reports/supervise.hpp
  // sets the soft limit alone, for this): V8's cages and WebAssembly's guard regions reserve tens
  // of GiB of address space they never touch, and Chromium does not start under 24 GiB.
  rlimit address_space{};
  const bool limited =
      getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != address_space.rlim_max;
  if (limited) {
    const rlimit open{address_space.rlim_max, address_space.rlim_max};
    setrlimit(RLIMIT_AS, &open);
  }
  const int spawned =
      posix_spawn(&pid_, executable.c_str(), &actions, &attributes, argv.data(), environ);
  if (limited) setrlimit(RLIMIT_AS, &address_space);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  close(child_in);
  close(child_out);
  if (log_fd >= 0) close(log_fd);
  if (spawned != 0) {
    pid_ = -1;
    stop();
    throw std::runtime_error("cannot run " + executable + ": " + std::strerror(spawned));
  }
  try {
    product_ = call("Browser.getVersion", json::object(), timeout_s, true).value("product", "");
    const std::string target =
        call("Target.createTarget", {{"url", "about:blank"}}, timeout_s, true).at("targetId");
    session_ =
        call("Target.attachToTarget", {{"targetId", target}, {"flatten", true}}, timeout_s, true)
            .at("sessionId");
    call("Page.enable", json::object(), timeout_s);
  } catch (const std::exception& e) {
    const std::string why = e.what() + log_tail(log_);
    stop();
    throw std::runtime_error(executable + " did not start as a headless browser: " + why);
  }
}

Chromium::~Chromium() {
  stop();
}

void Chromium::stop() {
  if (pid_ > 0 && to_browser_ >= 0) {
    try {
      send({{"id", next_id_++}, {"method", "Browser.close"}});
    } catch (const std::exception&) {
      // Gone already.
    }
  }
  if (to_browser_ >= 0) close(to_browser_);
  if (from_browser_ >= 0) close(from_browser_);
  to_browser_ = from_browser_ = -1;
  if (pid_ > 0) {
    // Five seconds to close, then the whole process group goes.
    bool exited = false;
    for (int k = 0; k < 500 && !exited; ++k) {
      int status = 0;
      exited = waitpid(pid_, &status, WNOHANG) == pid_;
      if (!exited) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    kill(-pid_, SIGKILL);
    if (!exited) waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  if (!log_.empty()) unlink(log_.c_str());
  log_.clear();
}

void Chromium::send(const json& message) {
  const std::string text = message.dump() + '\0';
  // A browser that has gone would raise SIGPIPE: it is blocked for this thread while writing,
  // and one raised is taken before it is unblocked.
  sigset_t pipe_signal, old;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_signal, &old);
  size_t written = 0;
  int error = 0;
  while (written < text.size()) {
    const ssize_t n = write(to_browser_, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      error = errno;
      break;
    }
    written += static_cast<size_t>(n);
  }
  if (error == EPIPE) {
    const timespec zero{0, 0};
    sigtimedwait(&pipe_signal, nullptr, &zero);
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  if (error)
    throw std::runtime_error(
        "Chromium: cannot send a command: " + std::string(std::strerror(error)) + log_tail(log_));
}

json Chromium::receive(double deadline) {
  for (;;) {  // each pass reads more or throws; the deadline bounds the waits
    if (const size_t end = pending_.find('\0', scanned_); end != std::string::npos) {
      json message =
          json::parse(pending_.begin(), pending_.begin() + static_cast<long>(end), nullptr, false);
      pending_.erase(0, end + 1);
      scanned_ = 0;
      if (message.is_discarded())
        throw std::runtime_error("Chromium sent a message that is not JSON");
      return message;
    }
    scanned_ = pending_.size();
    const double left = deadline - now_s();
    if (left <= 0.0) throw std::runtime_error("Chromium did not answer in time");
    pollfd p{from_browser_, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(left * 1000.0) + 1);
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) throw std::runtime_error(errno_text("Chromium: poll"));
    if (ready == 0) continue;  // the deadline check above ends it
    char buffer[1 << 16];
    const ssize_t n = read(from_browser_, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error("Chromium exited" + log_tail(log_));
    pending_.append(buffer, static_cast<size_t>(n));
  }
}

void Chromium::note(const json& event) {
  const std::string method = event.value("method", "");
  if (method == "Page.loadEventFired") ++loads_;
  if (method == "Inspector.targetCrashed" || method == "Target.targetCrashed") crashed_ = true;
}

json Chromium::call(const std::string& method, const json& params, double timeout_s, bool browser) {
  if (crashed_) throw std::runtime_error("Chromium's page crashed earlier" + log_tail(log_));
  const int id = next_id_++;
  json message = {{"id", id}, {"method", method}, {"params", params}};
  if (!browser) message["sessionId"] = session_;
  send(message);
  const double deadline = now_s() + timeout_s;
  for (;;) {  // receive() throws past the deadline
    json answer = receive(deadline);
    if (!answer.contains("id")) {
      note(answer);
      if (crashed_) throw std::runtime_error(method + ": Chromium's page crashed" + log_tail(log_));
      continue;
    }
    if (answer["id"] != id) continue;
    if (answer.contains("error"))
      throw std::runtime_error(method + ": " + answer["error"].value("message", "an error"));
    return answer.value("result", json::object());
  }
}

void Chromium::navigate(const std::string& url, double timeout_s) {
  const int before = loads_;
  const json result = call("Page.navigate", {{"url", url}}, timeout_s);
  if (result.contains("errorText") && !result["errorText"].get<std::string>().empty())
    throw std::runtime_error("Chromium cannot open " + url + ": " +
                             result["errorText"].get<std::string>());
  const double deadline = now_s() + timeout_s;
  while (loads_ == before) {  // receive() throws past the deadline
    note(receive(deadline));
    if (crashed_) throw std::runtime_error("Chromium's page crashed opening " + url);
  }
}

json Chromium::evaluate(const std::string& expression, double timeout_s) {
  const json r = call("Runtime.evaluate",
                      {{"expression", expression}, {"awaitPromise", true}, {"returnByValue", true}},
                      timeout_s);
  if (r.contains("exceptionDetails")) {
    const json& d = r["exceptionDetails"];
    std::string why = d.value("text", "an exception");
    if (d.contains("exception") && d["exception"].contains("description"))
      why = d["exception"]["description"].get<std::string>();
    throw std::runtime_error(why.substr(0, why.find('\n')));
  }
  return r.contains("result") && r["result"].contains("value") ? r["result"]["value"] : json();
}

}  // namespace flatmarch::webgl
