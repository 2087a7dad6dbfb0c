// The window's OpenGL drawing (OpenGL 1.x / 2.1 calls only, so Mesa's llvmpipe under Xvfb runs
// them): the image texture, the cell mode's rubber band, reading the framebuffer back.
#pragma once

#include <cstdint>
#include <vector>

namespace pt {
namespace viewer {

// (Re)allocates texture `tex` as w x h RGB8 from `rgb` (top row first), nearest filtering.
void gl_texture_init(unsigned tex, int w, int h, const uint8_t* rgb);
// Uploads the rectangle (x, y, w, h) of `rgb`, an image `row` pixels wide, into `tex`.
void gl_texture_update(unsigned tex, const uint8_t* rgb, int row, int x, int y, int w, int h);
// Clears the fw x fh framebuffer and draws `tex` over all of it (texture row 0 at the top).
void gl_draw_texture(unsigned tex, int fw, int fh);
// A rectangle's outline in window coordinates (ww x wh, y down), drawn over the image.
void gl_draw_band(double x0, double y0, double x1, double y1, int ww, int wh);
// The back buffer's fw x fh RGB pixels, top row first.
std::vector<uint8_t> gl_read_frame(int fw, int fh);

}  // namespace viewer
}  // namespace pt
