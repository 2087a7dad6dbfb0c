// The window's --script player (viewer_script.h).
#include "viewer_script.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "viewer_loop.h"

namespace pt {
namespace viewer {

int key_code(const std::string& name) {
  if (name == "Esc" || name == "Escape" || name == "esc") return GLFW_KEY_ESCAPE;
  if (name == "Space" || name == "space") return GLFW_KEY_SPACE;
  if (name.size() != 1) return -1;
  char c = name[0];
  if (c >= 'a' && c <= 'z') return GLFW_KEY_A + (c - 'a');
  if (c >= 'A' && c <= 'Z') return GLFW_KEY_A + (c - 'A');
  switch (c) {
    case '.': return GLFW_KEY_PERIOD;
    case ',': return GLFW_KEY_COMMA;
    case '\'': return GLFW_KEY_APOSTROPHE;
    case ';': return GLFW_KEY_SEMICOLON;
    case '[': return GLFW_KEY_LEFT_BRACKET;
    case ']': return GLFW_KEY_RIGHT_BRACKET;
    case '=': return GLFW_KEY_EQUAL;
    case '-': return GLFW_KEY_MINUS;
    case '`': return GLFW_KEY_GRAVE_ACCENT;
    case '/':
    case '?': return GLFW_KEY_SLASH;
    default: return -1;
  }
}

std::vector<ScriptLine> load_script(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open script");
  std::vector<ScriptLine> out;
  std::string text;
  for (int n = 1; std::getline(in, text); ++n) {
    std::istringstream ws(text);
    ScriptLine l{n, {}};
    for (std::string w; ws >> w;) l.words.push_back(w);
    if (l.words.empty() || l.words[0][0] == '#') continue;
    const std::string& c = l.words[0];
    size_t want_args = c == "wait_spp" || c == "wait_ms" || c == "key" || c == "screenshot" || c == "wheel" ? 1
                       : c == "click" || c == "resize"                                                      ? 2
                       : c == "drag"                                                                        ? 6
                       : c == "sync" || c == "title" || c == "overlay" || c == "close" || c == "quit" ? 0
                                                                                                            : size_t(-1);
    std::string where = path + ":" + std::to_string(n) + ": ";
    if (want_args == size_t(-1)) throw std::runtime_error(where + "unknown command '" + c + "'");
    if (l.words.size() != want_args + 1)
      throw std::runtime_error(where + c + " takes " + std::to_string(want_args) + " argument(s)");
    if (c == "key" && key_code(l.words[1]) < 0) throw std::runtime_error(where + "unknown key '" + l.words[1] + "'");
    if (c == "drag" && l.words[1] != "left" && l.words[1] != "right")
      throw std::runtime_error(where + "drag takes left or right, then X0 Y0 X1 Y1 STEPS");
    for (size_t i = c == "drag" ? 2 : 1; i < l.words.size() && c != "key" && c != "screenshot"; ++i) {
      char* end = nullptr;
      double v = std::strtod(l.words[i].c_str(), &end);
      if (c == "wheel" && *end == '\0' && std::isfinite(v)) continue;  // either way
      if (*end != '\0' || !(v >= 0)) throw std::runtime_error(where + "'" + l.words[i] + "' is not a number >= 0");
    }
    out.push_back(std::move(l));
  }
  return out;
}

namespace {
constexpr double kTimeoutMs = 120000;  // a wait that never ends fails the run
}

void ScriptPlayer::step(ScriptHost& host) {
  using Clock = std::chrono::steady_clock;
  auto ms = [this] { return std::chrono::duration<double, std::milli>(Clock::now() - m_started_at).count(); };
  while (m_pos < m_lines.size()) {
    const ScriptLine& l = m_lines[m_pos];
    const std::string& c = l.words[0];
    auto arg = [&](int i) { return std::strtod(l.words[i].c_str(), nullptr); };
    if (!m_started) {
      m_started = true;
      m_started_at = Clock::now();
      if (c == "resize") host.request_size(int(arg(1)), int(arg(2)));
    }
    bool done = true;
    if (c == "wait_spp") {
      done = host.reached(arg(1));
    } else if (c == "wait_ms") {
      done = ms() >= arg(1);
    } else if (c == "sync") {
      done = host.synced();
      if (done) say("sync: %.0f ms", ms());
    } else if (c == "resize") {
      done = host.rendering_at(int(arg(1)), int(arg(2)));
    } else if (c == "key") {
      host.key(key_code(l.words[1]));
    } else if (c == "click") {
      host.click(arg(1), arg(2));
    } else if (c == "drag") {  // press, STEPS moves along the line, release: as a hand would
      const int steps = std::max(1, int(arg(6)));
      const bool left = l.words[1] == "left";
      host.button(left, true, arg(2), arg(3));
      for (int k = 1; k <= steps; ++k)
        host.cursor(arg(2) + (arg(4) - arg(2)) * k / steps, arg(3) + (arg(5) - arg(3)) * k / steps);
      host.button(left, false, arg(4), arg(5));
    } else if (c == "wheel") {
      host.wheel(arg(1));
    } else if (c == "title") {
      say("title: %s", host.title().c_str());
    } else if (c == "overlay") {
      host.report_overlay();
    } else if (c == "screenshot") {
      host.screenshot(l.words[1]);
    } else if (c == "close" || c == "quit") {
      host.close(0);
    }
    if (!done) {
      if (ms() > kTimeoutMs) {
        std::fprintf(stderr, "pathtracer: %s:%d: '%s' timed out\n", m_path.c_str(), l.line, c.c_str());
        host.close(1);
      }
      return;
    }
    ++m_pos;
    m_started = false;
    if (c == "close" || c == "quit") return;
  }
}

}  // namespace viewer
}  // namespace pt
