#include "kernels/shader_log.hpp"

#include <algorithm>
#include <cstdio>
#include <regex>
#include <set>
#include <sstream>
#include <vector>

namespace flatmarch::kernel {

std::string annotate_log(const std::string& source, const std::string& log, int context) {
  std::vector<std::string> lines;
  std::istringstream in(source);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  // The lines errors name; the lines warnings name only when there is no error.
  std::set<int> named, warned;
  // Mesa writes "0:LINE(COLUMN): error: ...", NVIDIA's driver "0(LINE) : error C1503: ...",
  // glslang "ERROR: 0:LINE: ...".
  static const std::regex kMesa(R"((?:^|\n)\s*\d+:(\d+)\(\d+\):\s*(\w+))");
  static const std::regex kNvidia(R"((?:^|\n)\s*\d+\((\d+)\)\s*:\s*(\w+))");
  static const std::regex kGlslang(R"((?:^|\n)\s*(ERROR|WARNING):\s*\d+:(\d+):)");
  for (const std::regex* format : {&kMesa, &kNvidia})
    for (auto it = std::sregex_iterator(log.begin(), log.end(), *format);
         it != std::sregex_iterator(); ++it)
      ((*it)[2] == "error" ? named : warned).insert(std::stoi((*it)[1]));
  for (auto it = std::sregex_iterator(log.begin(), log.end(), kGlslang);
       it != std::sregex_iterator(); ++it)
    ((*it)[1] == "ERROR" ? named : warned).insert(std::stoi((*it)[2]));
  if (named.empty()) named = warned;
  std::string out = log;
  int shown_to = 0;  // the last line shown, so that nearby errors share their context
  for (const int n : named) {
    const int from = std::max({1, n - context, shown_to + 1});
    const int to = std::min(static_cast<int>(lines.size()), n + context);
    if (from > to) continue;
    out += "\n  ...\n";
    for (int k = from; k <= to; ++k) {
      char number[16];
      std::snprintf(number, sizeof number, "%5d", k);
      out += std::string(k == n ? ">" : " ") + number + "  " + lines[static_cast<size_t>(k - 1)] +
             "\n";
    }
    shown_to = to;
  }
  return out;
}

}  // namespace flatmarch::kernel
