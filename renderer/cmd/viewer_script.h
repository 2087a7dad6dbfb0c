// The window's script player, built into the test build of the command only (pathtracer-scripted,
// tests/pathtracer_scripted.cpp): `--script FILE` replays input from FILE, one command a line,
// through the window's own handlers (viewer.h, ScriptHost). The commands:
//   key K | click X Y | drag left|right X0 Y0 X1 Y1 STEPS | wheel STEPS | resize W H
//   wait_spp N | wait_ms MS | sync | title | overlay | screenshot FILE.png | close
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "viewer.h"

namespace pt {
namespace viewer {

struct ScriptLine {
  int line;
  std::vector<std::string> words;  // the command, then its arguments
};

// The GLFW key code of a key name in a script ("L", "]", "`", "Esc"), or -1.
int key_code(const std::string& name);
// Reads and checks the whole script up front; throws naming FILE:LINE.
std::vector<ScriptLine> load_script(const std::string& path);

class ScriptPlayer : public WindowScript {
 public:
  explicit ScriptPlayer(const std::string& path) : m_path(path), m_lines(load_script(path)) {}
  void step(ScriptHost& host) override;
  bool done() const override { return m_pos >= m_lines.size(); }

 private:
  std::string m_path;
  std::vector<ScriptLine> m_lines;
  size_t m_pos = 0;
  bool m_started = false;  // the current line's first step has run
  std::chrono::steady_clock::time_point m_started_at;
};

}  // namespace viewer
}  // namespace pt
