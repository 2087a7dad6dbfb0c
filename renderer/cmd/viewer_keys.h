// The window's settings keys (the course's RENDER-mode keys): each changes one render setting and
// restarts the render. Kept apart from the window so that the table is plain data and functions.
#pragma once

#include <string>

#include "options.h"

namespace pt {
namespace viewer {

// Applies settings key `key` (a GLFW key code: . , L K ' ; ] [ = -) to p and returns what it now
// says ("max depth 6"); empty when the key changes no setting.
std::string apply_setting_key(int key, RenderParams& p);
bool is_setting_key(int key);

}  // namespace viewer
}  // namespace pt
