#include "backends/simd/tuning.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace flatmarch::simd {

const char* isa_name(Isa isa) {
  switch (isa) {
    case Isa::avx512:
      return "avx512";
    case Isa::avx2:
      return "avx2";
    case Isa::sse4:
      return "sse4";
  }
  return "?";
}

#ifdef FLATMARCH_SIMD_TUNING_PROBE
namespace {
// "[isa.]name=value" pairs, comma-separated, applied to `t` where they name `isa` or none: a
// threshold's value, or a mode's (kModeNames) 1 to take it where a scene allows, 0 to leave it.
void override_from(const std::string& text, Isa isa, Tuning& t) {
  size_t at = 0;
  while (at < text.size()) {  // bounded: every turn moves past a comma or the end
    const size_t comma = std::min(text.find(',', at), text.size());
    const std::string part = text.substr(at, comma - at);
    at = comma + 1;
    const size_t eq = part.find('=');
    if (eq == std::string::npos)
      throw std::invalid_argument("FLATMARCH_SIMD_TUNE: no = in " + part);
    std::string name = part.substr(0, eq);
    if (const size_t dot = name.find('.'); dot != std::string::npos) {
      const std::string prefix = name.substr(0, dot);
      if (prefix != "avx512" && prefix != "avx2" && prefix != "sse4")
        throw std::invalid_argument("FLATMARCH_SIMD_TUNE: unknown instruction set in " + part);
      if (prefix != isa_name(isa)) continue;
      name = name.substr(dot + 1);
    }
    const std::string number = part.substr(eq + 1);
    int value = 0;
    size_t used = 0;
    try {
      value = std::stoi(number, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != number.size())
      throw std::invalid_argument("FLATMARCH_SIMD_TUNE: not a whole number in " + part);
    if (name == "refill_at")
      t.refill_at = value;
    else if (name == "refill_spread")
      t.refill_spread = value;
    else if (name == "patience")
      t.patience = value;
    else if (name == "patience_two_rooms")
      t.patience_two_rooms = value;
    else if (name == "most_vectors")
      t.most_vectors = value;
    else if (name == "most_vectors_analytic")
      t.most_vectors_analytic = value;
    else if (name == "rooms_per_pass")
      t.rooms_per_pass = value;
    else if (name == "held_over_lookup")
      t.held_over_lookup = value != 0;
    else if (const auto mode = std::find_if(kModeNames.begin(), kModeNames.end(),
                                            [&](const ModeName& m) { return name == m.name; });
             mode != kModeNames.end())
      t.modes = value != 0 ? t.modes | mode->mode : t.modes & ~static_cast<uint32_t>(mode->mode);
    else
      throw std::invalid_argument("FLATMARCH_SIMD_TUNE: unknown value " + name);
  }
}
}  // namespace

Tuning tuning(Isa isa) {
  Tuning t = kTunings[static_cast<size_t>(isa)];
  if (const char* text = std::getenv("FLATMARCH_SIMD_TUNE")) override_from(text, isa, t);
  return t;
}
#endif

}  // namespace flatmarch::simd
