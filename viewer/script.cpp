#include "viewer/script.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace flatmarch::viewer {

int key_by_name(const std::string& name) {
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (upper.size() == 1 && upper[0] >= 'A' && upper[0] <= 'Z')
    return GLFW_KEY_A + (upper[0] - 'A');  // GLFW's letter codes are their ASCII codes
  if (upper.size() == 1 && upper[0] >= '0' && upper[0] <= '9') return GLFW_KEY_0 + (upper[0] - '0');
  if (upper.size() >= 2 && upper.size() <= 3 && upper[0] == 'F' &&
      std::all_of(upper.begin() + 1, upper.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    const int n = std::stoi(upper.substr(1));
    if (n >= 1 && n <= 12) return GLFW_KEY_F1 + n - 1;
  }
  static const std::map<std::string, int> kNamed{
      {"TAB", GLFW_KEY_TAB},
      {"ESCAPE", GLFW_KEY_ESCAPE},
      {"ESC", GLFW_KEY_ESCAPE},
      {"SPACE", GLFW_KEY_SPACE},
      {"ENTER", GLFW_KEY_ENTER},
      {"SHIFT", GLFW_KEY_LEFT_SHIFT},
      {"LEFT_SHIFT", GLFW_KEY_LEFT_SHIFT},
      {"RIGHT_SHIFT", GLFW_KEY_RIGHT_SHIFT},
      {"MINUS", GLFW_KEY_MINUS},
      {"-", GLFW_KEY_MINUS},
      {"EQUAL", GLFW_KEY_EQUAL},
      {"=", GLFW_KEY_EQUAL},
      {"LEFT_BRACKET", GLFW_KEY_LEFT_BRACKET},
      {"[", GLFW_KEY_LEFT_BRACKET},
      {"RIGHT_BRACKET", GLFW_KEY_RIGHT_BRACKET},
      {"]", GLFW_KEY_RIGHT_BRACKET},
      {"SEMICOLON", GLFW_KEY_SEMICOLON},
      {";", GLFW_KEY_SEMICOLON},
      {"APOSTROPHE", GLFW_KEY_APOSTROPHE},
      {"'", GLFW_KEY_APOSTROPHE},
  };
  const auto it = kNamed.find(upper);
  return it == kNamed.end() ? -1 : it->second;
}

namespace {

std::string trim(const std::string& s) {
  const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
  const auto b = std::find_if_not(s.begin(), s.end(), space);
  const auto e = std::find_if_not(s.rbegin(), s.rend(), space).base();
  return b < e ? std::string(b, e) : std::string();
}

// Parses one line's arguments, throwing ScriptError that names the line.
class Line {
 public:
  Line(const std::string& name, int number, const std::string& text)
      : where_(name + ":" + std::to_string(number) + ": "), in_(text) {}

  [[noreturn]] void fail(const std::string& what) const { throw ScriptError(where_ + what); }

  std::string word(const char* what) {
    std::string w;
    if (!(in_ >> w)) fail(std::string("expected ") + what);
    return w;
  }
  double number(const char* what) {
    const std::string w = word(what);
    size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(w, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != w.size() || !std::isfinite(v))
      fail(std::string(what) + ": \"" + w + "\" is not a finite number");
    return v;
  }
  int key() {
    const std::string w = word("a key");
    const int k = key_by_name(w);
    if (k < 0) fail("unknown key \"" + w + "\" (see `flatmarch view --help`)");
    return k;
  }
  std::string rest(const char* what) {
    std::string r;
    std::getline(in_, r);
    r = trim(r);
    if (r.empty()) fail(std::string("expected ") + what);
    return r;
  }
  void end() {
    std::string extra;
    if (in_ >> extra) fail("unexpected \"" + extra + "\" at the end of the line");
  }

 private:
  std::string where_;
  std::istringstream in_;
};

}  // namespace

std::vector<ScriptStep> parse_script(std::istream& in, const std::string& name) {
  std::vector<ScriptStep> steps;
  int number = 0;
  for (std::string text; std::getline(in, text);) {
    ++number;
    text = trim(text);
    if (text.empty() || text[0] == '#') continue;
    Line line(name, number, text);
    ScriptStep step;
    step.line = number;
    const std::string command = line.word("a command");
    const auto frames_of = [&](double count, const char* what) {
      if (!(count >= 1.0 && count <= kMaxScriptFrames))
        line.fail(std::string(what) + " must come to 1 to " + std::to_string(kMaxScriptFrames) +
                  " frames of 1/30 s");
      return static_cast<int>(count);
    };
    if (command == "hold") {
      step.kind = ScriptStep::Kind::hold;
      step.key = line.key();
      step.frames = frames_of(std::round(line.number("SECONDS") / kScriptFrameTime), "SECONDS");
    } else if (command == "key") {
      step.kind = ScriptStep::Kind::key;
      step.key = line.key();
    } else if (command == "mouse") {
      step.kind = ScriptStep::Kind::mouse;
      step.dx = line.number("DX");
      step.dy = line.number("DY");
      if (std::abs(step.dx) > 1e6 || std::abs(step.dy) > 1e6)
        line.fail("DX and DY must lie within 1e6 pixels");
    } else if (command == "click") {
      step.kind = ScriptStep::Kind::click;
    } else if (command == "frames") {
      step.kind = ScriptStep::Kind::frames;
      const double n = line.number("N");
      if (n != std::floor(n)) line.fail("N must be a whole number");
      step.frames = frames_of(n, "N");
    } else if (command == "screenshot" || command == "state") {
      step.kind = command == "state" ? ScriptStep::Kind::state : ScriptStep::Kind::screenshot;
      step.path = line.rest("PATH");
      steps.push_back(step);
      continue;
    } else {
      line.fail("unknown command \"" + command +
                "\" (hold, key, mouse, click, frames, screenshot, state)");
    }
    line.end();
    steps.push_back(step);
  }
  return steps;
}

std::vector<ScriptStep> load_script(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw ScriptError(path.string() + ": cannot read the script");
  return parse_script(in, path.string());
}

}  // namespace flatmarch::viewer
