#include "tests/backends/faults.hpp"

#include <array>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <utility>

namespace flatmarch::test {
namespace {

constexpr std::array<std::pair<const char*, Fault::Kind>, 7> kKinds{
    {{"crash", Fault::Kind::crash},
     {"abort", Fault::Kind::abort},
     {"hang", Fault::Kind::hang},
     {"oom", Fault::Kind::oom},
     {"nan", Fault::Kind::nan},
     {"flip", Fault::Kind::flip},
     {"sleep", Fault::Kind::sleep}}};

Fault parse_fault(const std::string& item) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument(
        "FLATMARCH_FAULTY: '" + item + "': " + why +
        " (FAULT[=SCENE[/METHOD]], FAULT one of crash, abort, hang, oom, nan, "
        "flip, sleep:SECONDS)");
  };
  Fault f;
  std::string kind = item;
  if (const size_t eq = item.find('='); eq != std::string::npos) {
    kind = item.substr(0, eq);
    f.scene = item.substr(eq + 1);
    if (const size_t slash = f.scene.find('/'); slash != std::string::npos) {
      f.method = f.scene.substr(slash + 1);
      f.scene.resize(slash);
      if (f.method.empty()) throw bad("no method after '/'");
    }
    if (f.scene.empty()) throw bad("no scene after '='");
  }
  std::string seconds;
  if (const size_t colon = kind.find(':'); colon != std::string::npos) {
    seconds = kind.substr(colon + 1);
    kind = kind.substr(0, colon);
  }
  bool known = false;
  for (const auto& [name, k] : kKinds)
    if (kind == name) {
      f.kind = k;
      known = true;
    }
  if (!known) throw bad("unknown fault '" + kind + "'");
  if (f.kind == Fault::Kind::sleep) {
    if (seconds.empty()) throw bad("sleep needs its seconds, e.g. sleep:2");
    size_t used = 0;
    try {
      f.seconds = std::stod(seconds, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != seconds.size() || !std::isfinite(f.seconds) || f.seconds < 0.0 ||
        f.seconds > 3600.0)
      throw bad("'" + seconds + "' is not a number of seconds from 0 to 3600");
  } else if (!seconds.empty()) {
    throw bad("only sleep takes seconds");
  }
  return f;
}

}  // namespace

std::vector<Fault> parse_faults(const std::string& text) {
  std::vector<Fault> faults;
  size_t start = 0;
  while (start <= text.size() && !text.empty()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    if (item.empty())
      throw std::invalid_argument("FLATMARCH_FAULTY: an empty item in '" + text + "'");
    faults.push_back(parse_fault(item));
    start = comma + 1;
  }
  return faults;
}

std::vector<Fault> faults_from_environment() {
  const char* text = std::getenv("FLATMARCH_FAULTY");
  return text ? parse_faults(text) : std::vector<Fault>{};
}

std::optional<Fault> fault_for(const std::vector<Fault>& faults, const std::string& scene,
                               const std::string& method) {
  for (const Fault& f : faults)
    if (f.scene == scene && f.method == method) return f;
  for (const Fault& f : faults)
    if (f.scene == scene && f.method.empty()) return f;
  for (const Fault& f : faults)
    if (f.scene.empty()) return f;
  return std::nullopt;
}

}  // namespace flatmarch::test
