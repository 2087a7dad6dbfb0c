// The GLFW debug window (`pathtracer scene.dae` without -f): the progressive render as it
// converges, a status panel and rate legend over it, the course's render-mode keys,
// click-to-focus, camera moves, cell mode, and a script player for tests. viewer.cpp,
// viewer_gl.cpp, viewer_script.cpp and overlay.cpp are the only files that include GLFW / OpenGL; they are linked into the pathtracer executable
// only, never into the renderer library.
#pragma once

#include "cli.h"

namespace pt {

// Opens the window and renders until it is closed. Returns the exit status: 0 when closed,
// 1 on a scene, render or --script error, 2 when no window can be opened (no display).
int run_viewer(const CliOptions& options);

}  // namespace pt
