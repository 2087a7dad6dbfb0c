// The window's --script player: the file format (usage_text lists the commands) and its checks.
// The commands themselves run in viewer.cpp, through the same functions as real input.
#pragma once

#include <string>
#include <vector>

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

}  // namespace viewer
}  // namespace pt
