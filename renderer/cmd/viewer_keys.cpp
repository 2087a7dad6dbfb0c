// The settings keys (viewer_keys.h): the course's steps and limits for each.
#include "viewer_keys.h"

#include <GLFW/glfw3.h>

#include <algorithm>

#include "viewer_loop.h"

namespace pt {
namespace viewer {

namespace {

std::string step_lens(RenderParams& p, float step) {
  p.lens_radius = std::max(0.0f, p.lens_radius + step);
  if (p.lens_radius < 1e-6f) p.lens_radius = 0;
  return "lens radius " + fmt_g(p.lens_radius);
}

std::string step_focus(RenderParams& p, float step) {
  p.focal_distance = std::min(std::max(0.0f, p.focal_distance + step), 1e12f);
  if (p.focal_distance < 1e-6f) p.focal_distance = 0;
  return "focal distance " + fmt_g(p.focal_distance);
}

}  // namespace

bool is_setting_key(int key) {
  switch (key) {
    case GLFW_KEY_PERIOD: case GLFW_KEY_COMMA: case GLFW_KEY_L: case GLFW_KEY_K: case GLFW_KEY_APOSTROPHE:
    case GLFW_KEY_SEMICOLON: case GLFW_KEY_RIGHT_BRACKET: case GLFW_KEY_LEFT_BRACKET: case GLFW_KEY_EQUAL:
    case GLFW_KEY_MINUS:
      return true;
    default:
      return false;
  }
}

std::string apply_setting_key(int key, RenderParams& p) {
  switch (key) {
    case GLFW_KEY_PERIOD:
      p.max_depth = std::min(p.max_depth + 1, 1000000);
      return "max depth " + std::to_string(p.max_depth);
    case GLFW_KEY_COMMA:
      p.max_depth = std::max(p.max_depth - 1, 0);
      return "max depth " + std::to_string(p.max_depth);
    case GLFW_KEY_L: return step_lens(p, +0.05f);
    case GLFW_KEY_K: return step_lens(p, -0.05f);
    case GLFW_KEY_APOSTROPHE: return step_focus(p, +0.1f);
    case GLFW_KEY_SEMICOLON: return step_focus(p, -0.1f);
    case GLFW_KEY_RIGHT_BRACKET:
      p.spp = std::min(p.spp * 2, 1 << 24);
      return "spp " + std::to_string(p.spp);
    case GLFW_KEY_LEFT_BRACKET:
      p.spp = std::max(p.spp / 2, 1);
      return "spp " + std::to_string(p.spp);
    case GLFW_KEY_EQUAL:
      p.light_samples = std::min(p.light_samples * 2, 65536);
      return "light samples " + std::to_string(p.light_samples);
    case GLFW_KEY_MINUS:
      p.light_samples = std::max(p.light_samples / 2, 1);
      return "light samples " + std::to_string(p.light_samples);
    default:
      return "";
  }
}

}  // namespace viewer
}  // namespace pt
