// Headless Chromium driven through the DevTools protocol over a pipe (--remote-debugging-pipe:
// the browser reads commands, JSON texts each ended by a NUL byte, from its file descriptor 3 and
// answers on 4). The webgl backend opens its pages in one; the web benchmarks time pages in one.
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace flatmarch::webgl {

// The Chromium to run: $FLATMARCH_CHROMIUM if set, else the first of chromium, chromium-browser,
// google-chrome on PATH; none if there is none.
std::optional<std::string> find_chromium();

// Chromium's flags for the webgl backend's --device: "" lets Chromium choose (a GPU where it can
// use one, else SwiftShader), "swiftshader" or "cpu" asks for SwiftShader, "gpu" for the GPU
// (ANGLE on OpenGL). Throws std::invalid_argument on another.
std::vector<std::string> device_flags(const std::string& device);

class Chromium {
 public:
  // Starts `executable` headless with `flags` added (--disable-gpu: WebGL on SwiftShader), opens
  // a blank page and attaches to it. Throws std::runtime_error, saying why, if the browser does
  // not start or answer within `timeout_s`.
  Chromium(const std::string& executable, const std::vector<std::string>& flags,
           double timeout_s = 60.0);
  ~Chromium();
  Chromium(const Chromium&) = delete;
  Chromium& operator=(const Chromium&) = delete;

  // Calls a protocol method on the page (`browser`: on the browser itself) and returns its
  // result. Throws std::runtime_error on the protocol's error, on no answer within `timeout_s`,
  // or when the browser has gone.
  nlohmann::json call(const std::string& method,
                      const nlohmann::json& params = nlohmann::json::object(),
                      double timeout_s = 60.0, bool browser = false);
  // Opens `url` in the page and waits for its load event.
  void navigate(const std::string& url, double timeout_s = 60.0);
  // Evaluates a JavaScript expression in the page, waiting for it if it is a promise, and returns
  // its value (as JSON). A thrown exception becomes a std::runtime_error with its message.
  nlohmann::json evaluate(const std::string& expression, double timeout_s = 60.0);
  // "HeadlessChrome/156.0.8078.108"
  const std::string& product() const { return product_; }

 private:
  void send(const nlohmann::json& message);
  nlohmann::json receive(double deadline);  // the next message; throws past the deadline
  void note(const nlohmann::json& event);   // an event: counts loads, notes a crash
  void stop();

  pid_t pid_ = -1;
  int to_browser_ = -1, from_browser_ = -1;
  std::string pending_;  // bytes read past the last message
  size_t scanned_ = 0;   // of which this many hold no NUL
  std::string log_;      // the browser's stdout and stderr
  int loads_ = 0;        // load events seen
  bool crashed_ = false;
  int next_id_ = 1;
  std::string session_, product_;
};

}  // namespace flatmarch::webgl
