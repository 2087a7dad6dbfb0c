// The window's OpenGL drawing (viewer_gl.h).
#include "viewer_gl.h"

#include <GLFW/glfw3.h>

#include <algorithm>

namespace pt {
namespace viewer {

void gl_texture_init(unsigned tex, int w, int h, const uint8_t* rgb) {
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
  glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, w, h, 0, GL_RGB, GL_UNSIGNED_BYTE, rgb);
}

void gl_texture_update(unsigned tex, const uint8_t* rgb, int row, int x, int y, int w, int h) {
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, row);
  glPixelStorei(GL_UNPACK_SKIP_PIXELS, x);
  glPixelStorei(GL_UNPACK_SKIP_ROWS, y);
  glTexSubImage2D(GL_TEXTURE_2D, 0, x, y, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb);
}

void gl_draw_texture(unsigned tex, int fw, int fh) {
  glViewport(0, 0, fw, fh);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  if (tex == 0) return;
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glDisable(GL_BLEND);
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_TEXTURE_2D);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_REPLACE);
  glColor4f(1, 1, 1, 1);
  glBegin(GL_QUADS);
  glTexCoord2f(0, 1); glVertex2f(-1, -1);
  glTexCoord2f(1, 1); glVertex2f(1, -1);
  glTexCoord2f(1, 0); glVertex2f(1, 1);
  glTexCoord2f(0, 0); glVertex2f(-1, 1);
  glEnd();
  glDisable(GL_TEXTURE_2D);
}

void gl_draw_band(double x0, double y0, double x1, double y1, int ww, int wh) {
  if (ww <= 0 || wh <= 0) return;
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glDisable(GL_TEXTURE_2D);
  auto nx = [&](double x) { return float(2 * x / ww - 1); };
  auto ny = [&](double y) { return float(1 - 2 * y / wh); };
  // Two outlines, black under white, so the band shows on any image.
  for (int pass = 0; pass < 2; ++pass) {
    glLineWidth(pass == 0 ? 3.0f : 1.0f);
    glColor4f(pass, pass, pass, 1);
    glBegin(GL_LINE_LOOP);
    glVertex2f(nx(x0), ny(y0));
    glVertex2f(nx(x1), ny(y0));
    glVertex2f(nx(x1), ny(y1));
    glVertex2f(nx(x0), ny(y1));
    glEnd();
  }
  glLineWidth(1.0f);
}

std::vector<uint8_t> gl_read_frame(int fw, int fh) {
  std::vector<uint8_t> rows(size_t(fw) * fh * 3), top_first(rows.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, fw, fh, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  const size_t stride = size_t(fw) * 3;
  for (int y = 0; y < fh; ++y)
    std::copy(rows.begin() + (fh - 1 - y) * stride, rows.begin() + (fh - y) * stride, top_first.begin() + y * stride);
  return top_first;
}

}  // namespace viewer
}  // namespace pt
