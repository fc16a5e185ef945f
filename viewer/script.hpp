// Scripted input for tests and demos (`flatmarch view --script FILE`): a list of input events
// that the viewer feeds through the same handlers as real input, one simulated frame of
// kScriptFrameTime at a time, so that the camera's motion is the same on every machine.
//
// One command a line; blank lines and lines starting with # are skipped:
//   hold KEY SECONDS   hold KEY down for SECONDS of simulated time (rounded to whole frames)
//   key KEY            press and release KEY (as one tap between two frames)
//   mouse DX DY        move the mouse by DX, DY pixels (x right, y down)
//   click              press the left mouse button (recaptures a released cursor)
//   frames N           draw N frames with nothing held
//   screenshot PATH    save a screenshot PNG (as F12 does, but to PATH)
//   state PATH         write the viewer's state as JSON to PATH
// KEY is a letter, a digit, one of - = [ ] ; ' or a name: TAB, ESCAPE, SPACE, ENTER, SHIFT,
// LEFT_SHIFT, RIGHT_SHIFT, F1 ... F12, MINUS, EQUAL, LEFT_BRACKET, RIGHT_BRACKET, SEMICOLON,
// APOSTROPHE (any case). Relative paths are relative to the current directory.
#pragma once

#include <filesystem>
#include <istream>
#include <stdexcept>
#include <string>
#include <vector>

namespace flatmarch::viewer {

inline constexpr double kScriptFrameTime = 1.0 / 30.0;
// A hold or frames command runs this many frames at most (an hour of simulated time).
inline constexpr int kMaxScriptFrames = 108000;

// A script that cannot be read or parsed: "FILE:LINE: what is wrong".
class ScriptError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ScriptStep {
  enum class Kind { hold, key, mouse, click, frames, screenshot, state };
  Kind kind = Kind::frames;
  int line = 0;  // in the script, from 1
  int key = 0;   // hold, key: a GLFW key code
  int frames = 0;
  double dx = 0.0, dy = 0.0;
  std::string path;
};

std::vector<ScriptStep> parse_script(std::istream& in, const std::string& name);
std::vector<ScriptStep> load_script(const std::filesystem::path& path);

// The GLFW key code of a KEY as scripts name it, or -1.
int key_by_name(const std::string& name);

}  // namespace flatmarch::viewer
