// The debug window's overlay (overlay.h).
#include "overlay.h"

#include <GL/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <utility>

#include "bitmap_font.h"

namespace pt {
namespace viewer {

namespace {

// The text scale a framebuffer asks for before fitting: 1 up to 800x600, then one more for each
// 400x300 (a HiDPI framebuffer of the same window gets bigger text).
int preferred_scale(int fw, int fh) { return std::max(1, std::min({fw / 400, fh / 300, 8})); }

int text_width(size_t chars, int s) { return chars == 0 ? 0 : int(chars) * kCellW * s - s; }

size_t longest(const std::vector<std::string>& lines) {
  size_t n = 0;
  for (const std::string& l : lines) n = std::max(n, l.size());
  return n;
}

// Quads for the lit font pixels of `text` with its top-left at (x, y); inside glBegin(GL_QUADS).
void emit_text(int x, int y, int s, const std::string& text) {
  for (size_t i = 0; i < text.size(); ++i)
    for (int gy = 0; gy < kGlyphH; ++gy)
      for (int gx = 0; gx < kGlyphW; ++gx) {
        if (!glyph_lit(text[i], gx, gy)) continue;
        int px = x + (int(i) * kCellW + gx) * s, py = y + gy * s;
        glVertex2i(px, py);
        glVertex2i(px + s, py);
        glVertex2i(px + s, py + s);
        glVertex2i(px, py + s);
      }
}

void emit_rect(const Rect& r) {
  glVertex2i(r.x, r.y);
  glVertex2i(r.x + r.w, r.y);
  glVertex2i(r.x + r.w, r.y + r.h);
  glVertex2i(r.x, r.y + r.h);
}

// Pixel-exact 2D drawing in framebuffer pixels (top-left origin), clipped to `clip`.
void begin_2d(int fw, int fh, const Rect& clip) {
  glViewport(0, 0, fw, fh);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glOrtho(0, fw, fh, 0, -1, 1);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glDisable(GL_TEXTURE_2D);
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glEnable(GL_SCISSOR_TEST);
  glScissor(clip.x, fh - clip.y - clip.h, std::max(0, clip.w), std::max(0, clip.h));
}

void end_2d() {
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_BLEND);
}

// The backdrop darkens the image to 40% so that white text reads over any render.
void draw_backdrop(const Rect& r) {
  glColor4f(0, 0, 0, 0.6f);
  glBegin(GL_QUADS);
  emit_rect(r);
  glEnd();
}

std::string seconds_text(double s) {
  char buf[32];
  if (s < 10) std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%.0fs", s);
  else std::snprintf(buf, sizeof buf, "%.1fh", s / 3600);
  return buf;
}

}  // namespace

namespace {

std::string spp_text(const Status& st, bool current) {
  if (!current) return "restarting";
  return "spp " + std::to_string(st.reached_spp) + "/" + std::to_string(st.spp) + (st.finished ? " done" : "");
}

// "ETA 3s, 12%", counted down since the pass that made the estimate; empty when there is none.
std::string eta_text(const Status& st, bool current) {
  if (!current || st.finished || st.eta < 0) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "ETA %s, %.0f%%", seconds_text(std::max(0.0, st.eta - ms_since(st.at) / 1000)).c_str(),
                100 * st.progress);
  return buf;
}

}  // namespace

std::string progress_text(const Status& st, bool current) {
  std::string eta = eta_text(st, current);
  return spp_text(st, current) + (eta.empty() ? "" : " | " + eta);
}

std::vector<std::string> status_lines(const Status& st, const RenderParams& p, bool current, const std::string& view) {
  std::vector<std::string> l;
  l.push_back(spp_text(st, current));
  l.push_back("error " + format_error_estimate(current ? st.error : INFINITY));
  std::string eta = eta_text(st, current);
  l.push_back(current && st.finished ? "took " + seconds_text(st.seconds) : eta.empty() ? "ETA -" : eta);
  l.push_back("max depth " + std::to_string(p.max_depth));
  l.push_back("lens radius " + fmt_g(p.lens_radius));
  l.push_back("focal dist " + fmt_g(p.focal_distance));
  l.push_back("light samples " + std::to_string(p.light_samples));
  l.push_back("view " + view);
  l.push_back("H hide, ? keys");
  return l;
}

std::vector<std::string> key_lines() {
  // The brief form, the key column padded to the longest key: it fits a 320x240 window.
  size_t width = 0;
  for (const WindowKey& k : window_keys()) width = std::max(width, std::strlen(k.keys));
  std::vector<std::string> out;
  for (const WindowKey& k : window_keys()) out.push_back(k.keys + std::string(width + 2 - std::strlen(k.keys), ' ') + k.brief);
  return out;
}

PanelLayout layout_panel(std::vector<std::string> lines, int fw, int fh, int bottom) {
  PanelLayout l;
  bottom = std::min(bottom, fh);
  auto size = [&](int s, size_t n) {
    int pad = 2 * s;
    return Rect{2 * s, 2 * s, 2 * pad + text_width(longest(lines), s), 2 * pad + int(n) * kCellH * s - 2 * s};
  };
  int s = preferred_scale(fw, fh);
  for (; s > 1; --s) {
    Rect r = size(s, lines.size());
    if (r.x + r.w <= fw - r.x && r.y + r.h <= bottom - r.y) break;
  }
  // At scale 1 the window may still be too small: keep the lines that fit, clip the rest.
  while (lines.size() > 1 && size(s, lines.size()).h > bottom - 4 * s) lines.pop_back();
  l.rect = size(s, lines.size());
  l.rect.w = std::max(0, std::min(l.rect.w, fw - 2 * l.rect.x));
  l.rect.h = std::max(0, std::min(l.rect.h, bottom - 2 * l.rect.y));
  l.scale = s;
  l.lines = std::move(lines);
  return l;
}

LegendLayout layout_legend(int fw, int fh) {
  LegendLayout l;
  int s = preferred_scale(fw, fh);
  auto size = [&](int s) {
    int pad = 2 * s;
    // Text row, ramp, text row.
    return Rect{2 * s, 0, 2 * pad + 160 * s, 2 * pad + kCellH * s + 4 * s + 2 * s + kGlyphH * s};
  };
  // The legend takes at most a third of the height, so that the panel keeps some lines above it.
  for (; s > 1; --s) {
    Rect r = size(s);
    if (r.w <= fw - 2 * r.x && r.h <= fh / 3) break;
  }
  Rect r = size(s);
  r.w = std::max(0, std::min(r.w, fw - 2 * r.x));
  r.y = std::max(0, fh - r.x - r.h);
  l.rect = r;
  l.scale = s;
  int pad = 2 * s;
  l.bar = Rect{r.x + pad, r.y + pad + kCellH * s, std::max(1, r.w - 2 * pad), 4 * s};
  return l;
}

Overlay layout_overlay(const OverlayInputs& in, int fw, int fh) {
  Overlay o;
  o.spp = std::max(1, in.status.spp);
  o.min_count = in.min_count;
  o.max_count = in.max_count;
  o.legend = in.show_panel && in.show_rate && in.have_image;
  int bottom = fh;
  if (o.legend) {
    o.legend_layout = layout_legend(fw, fh);
    bottom = o.legend_layout.rect.y;
  }
  o.panel = in.show_panel || in.show_keys;
  if (o.panel)
    o.panel_layout = layout_panel(in.show_keys ? key_lines() : status_lines(in.status, in.params, in.current,
                                                                          in.show_rate       ? "sample rate"
                                                                          : in.show_denoised ? "denoised"
                                                                                             : "radiance"),
                                  fw, fh, bottom);
  return o;
}

std::string overlay_report(const Overlay& o, int fw, int fh) {
  auto rect = [](const Rect& r) {
    return std::to_string(r.x) + " " + std::to_string(r.y) + " " + std::to_string(r.w) + " " + std::to_string(r.h);
  };
  std::string text = "overlay: framebuffer " + std::to_string(fw) + "x" + std::to_string(fh);
  if (o.panel) text += " | panel " + rect(o.panel_layout.rect) + " scale " + std::to_string(o.panel_layout.scale);
  if (o.legend)
    text += " | legend " + rect(o.legend_layout.rect) + " bar " + rect(o.legend_layout.bar) + " samples " +
            std::to_string(o.min_count) + ".." + std::to_string(o.max_count) + " of " + std::to_string(o.spp);
  for (const std::string& l : o.panel_layout.lines) text += " | " + l;
  return text;
}

namespace {

void draw_panel(const PanelLayout& l, int fw, int fh) {
  begin_2d(fw, fh, l.rect);
  draw_backdrop(l.rect);
  const int s = l.scale, pad = 2 * s;
  glColor4f(1, 1, 1, 1);
  glBegin(GL_QUADS);
  for (size_t i = 0; i < l.lines.size(); ++i) emit_text(l.rect.x + pad, l.rect.y + pad + int(i) * kCellH * s, s, l.lines[i]);
  glEnd();
  end_2d();
}

// The ramp runs from 0 to spp samples in the rate image's colours; white ticks mark the image's
// fewest (min_count) and most (max_count) samples in a pixel, which the text above names.
void draw_legend(const LegendLayout& l, int fw, int fh, int spp, uint32_t min_count, uint32_t max_count) {
  begin_2d(fw, fh, l.rect);
  draw_backdrop(l.rect);
  const int s = l.scale;
  const Rect& bar = l.bar;
  spp = std::max(spp, 1);
  glBegin(GL_QUADS);
  // One column per pixel: the rate colours are piecewise linear only before tone mapping.
  for (int i = 0; i < bar.w; ++i) {
    double count = bar.w > 1 ? double(i) * spp / (bar.w - 1) : spp;
    Vec3 c = rate_colour(uint32_t(std::lround(count)), spp);
    glColor4ub(tonemap_course(c[0]), tonemap_course(c[1]), tonemap_course(c[2]), 255);
    emit_rect({bar.x + i, bar.y, 1, bar.h});
  }
  glColor4f(1, 1, 1, 1);
  for (uint32_t n : {min_count, max_count}) {
    int x = bar.x + int(std::lround(double(std::min<uint32_t>(n, uint32_t(spp))) / spp * (bar.w - 1)));
    emit_rect({x - s / 2, bar.y - s, s, bar.h + 2 * s});
  }
  const int top = l.rect.y + 2 * s, below = bar.y + bar.h + 2 * s;
  emit_text(bar.x, top, s, "samples " + std::to_string(min_count) + ".." + std::to_string(max_count));
  const std::string lo = "0", hi = std::to_string(spp), mid = std::to_string(spp / 2);
  emit_text(bar.x, below, s, lo);
  emit_text(bar.x + bar.w - text_width(hi.size(), s), below, s, hi);
  if (spp > 1 && bar.w >= text_width(lo.size() + mid.size() + hi.size() + 4, s))
    emit_text(bar.x + int(double(bar.w - 1) * (spp / 2) / spp) - text_width(mid.size(), s) / 2, below, s, mid);
  glEnd();
  end_2d();
}

}  // namespace

void draw_overlay(const Overlay& o, int fw, int fh) {
  if (o.legend) draw_legend(o.legend_layout, fw, fh, o.spp, o.min_count, o.max_count);
  if (o.panel) draw_panel(o.panel_layout, fw, fh);
}

}  // namespace viewer
}  // namespace pt
