// The debug window's overlay: the status panel (samples, error estimate, ETA, max depth, lens,
// focal distance, light samples, view) and the sample-rate legend, drawn over the image in the
// 5x7 bitmap font (bitmap_font.h) with OpenGL 1.x quads, as viewer.cpp draws the image. Layout is
// plain arithmetic, apart from the GL calls, so that the window's log can report where it drew.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "viewer_loop.h"

namespace pt {
namespace viewer {

struct Rect {
  int x = 0, y = 0, w = 0, h = 0;  // framebuffer pixels, top-left origin
};

// The status panel's lines, most important first: a window too small for all shows the first.
// `view`: what the image shows ("radiance", "sample rate", "denoised").
std::vector<std::string> status_lines(const Status& st, const RenderParams& p, bool current, const std::string& view);
// The key list in the panel's brief form (window_keys), for the ? key.
std::vector<std::string> key_lines();
// Samples, progress and ETA in a few words ("spp 8/64 | ETA 3s, 12%"): the window title's status.
std::string progress_text(const Status& st, bool current);

struct PanelLayout {
  Rect rect;
  int scale = 1;  // framebuffer pixels per font pixel
  std::vector<std::string> lines;
};
// The panel in the top-left corner above `bottom` (the legend's top, or the framebuffer height):
// its text grows with the framebuffer, shrinks to fit, and below scale 1 loses lines from the end.
PanelLayout layout_panel(std::vector<std::string> lines, int fw, int fh, int bottom);

struct LegendLayout {
  Rect rect, bar;  // the legend's backdrop and its colour ramp
  int scale = 1;
};
// The rate legend across the bottom-left of the framebuffer.
LegendLayout layout_legend(int fw, int fh);

// What the overlay is drawn over and which of its parts are on (the window's state).
struct OverlayInputs {
  Status status;
  RenderParams params;
  bool current = false;  // the status is the session of `params`
  bool show_panel = true, show_keys = false, show_rate = false, have_image = false;
  bool show_denoised = false;  // the denoised picture is shown (N)
  uint32_t min_count = 0, max_count = 0;  // the image's fewest and most samples in a pixel
};

struct Overlay {
  bool panel = false, legend = false;
  PanelLayout panel_layout;
  LegendLayout legend_layout;
  int spp = 1;
  uint32_t min_count = 0, max_count = 0;
};

// The panel (the status, or the keys after H) and, in the rate view, the legend below it. The `
// key hides both; H shows the keys even then.
Overlay layout_overlay(const OverlayInputs& in, int fw, int fh);
// Draws in the current GL context over whatever is there.
void draw_overlay(const Overlay& o, int fw, int fh);
// One log line: the framebuffer size, where the panel and legend are (framebuffer pixels, top-left
// origin), the legend's sample range, then the panel's lines; the tests read it.
std::string overlay_report(const Overlay& o, int fw, int fh);

}  // namespace viewer
}  // namespace pt
