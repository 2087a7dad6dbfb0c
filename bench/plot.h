// A log-log line plot drawn straight into an ImageRGB (no plotting library): decade grid,
// axes, tick labels and a legend in a 3x5 pixel font. Colours are given as display (sRGB-ish)
// values and stored so that write_image's course tone mapping shows them as given.
#pragma once

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "image.h"

namespace bench {

struct Series {
  std::string label;
  pt::Vec3 colour;  // display values in [0, 1]
  bool dashed = false;
  std::vector<double> x, y;
  Series(std::string l, pt::Vec3 c, bool d = false) : label(std::move(l)), colour(c), dashed(d) {}
};

namespace plot_detail {

// 3x5 glyphs, one row a number, bit 2 the left column.
inline const unsigned char* glyph(char c) {
  static const unsigned char letters[26][5] = {
      {2, 5, 7, 5, 5}, {6, 5, 6, 5, 6}, {3, 4, 4, 4, 3}, {6, 5, 5, 5, 6}, {7, 4, 6, 4, 7}, {7, 4, 6, 4, 4},
      {3, 4, 5, 5, 3}, {5, 5, 7, 5, 5}, {7, 2, 2, 2, 7}, {1, 1, 1, 5, 2}, {5, 5, 6, 5, 5}, {4, 4, 4, 4, 7},
      {5, 7, 7, 5, 5}, {6, 5, 5, 5, 5}, {2, 5, 5, 5, 2}, {6, 5, 6, 4, 4}, {2, 5, 5, 6, 3}, {6, 5, 6, 5, 5},
      {3, 4, 2, 1, 6}, {7, 2, 2, 2, 2}, {5, 5, 5, 5, 7}, {5, 5, 5, 5, 2}, {5, 5, 7, 7, 5}, {5, 5, 2, 5, 5},
      {5, 5, 2, 2, 2}, {7, 1, 2, 4, 7}};
  static const unsigned char digits[10][5] = {{7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {6, 1, 2, 4, 7}, {6, 1, 2, 1, 6},
                                              {5, 5, 7, 1, 1}, {7, 4, 6, 1, 6}, {3, 4, 7, 5, 7}, {7, 1, 2, 2, 2},
                                              {7, 5, 7, 5, 7}, {7, 5, 7, 1, 6}};
  static const unsigned char minus[5] = {0, 0, 7, 0, 0}, dot[5] = {0, 0, 0, 0, 2}, slash[5] = {1, 1, 2, 4, 4},
                             lpar[5] = {2, 4, 4, 4, 2}, rpar[5] = {2, 1, 1, 1, 2}, eq[5] = {0, 7, 0, 7, 0},
                             colon[5] = {0, 2, 0, 2, 0}, blank[5] = {0, 0, 0, 0, 0};
  c = char(std::toupper(static_cast<unsigned char>(c)));
  if (c >= 'A' && c <= 'Z') return letters[c - 'A'];
  if (c >= '0' && c <= '9') return digits[c - '0'];
  switch (c) {
    case '-': return minus;
    case '.': return dot;
    case '/': return slash;
    case '(': return lpar;
    case ')': return rpar;
    case '=': return eq;
    case ':': return colon;
    default: return blank;
  }
}

}  // namespace plot_detail

class Canvas {
 public:
  Canvas(int w, int h) {
    img.width = w;
    img.height = h;
    img.pixels.assign(size_t(w) * h, linear({1, 1, 1}));
  }
  // Display value -> the linear value that write_image's tone map turns back into it.
  static pt::Vec3 linear(pt::Vec3 d) {
    auto f = [](float v) { return std::pow(std::clamp(v, 0.0f, 1.0f), 2.2f) / std::sqrt(2.0f); };
    return {f(d.x), f(d.y), f(d.z)};
  }
  void set(int x, int y, pt::Vec3 display) {
    if (x >= 0 && y >= 0 && x < img.width && y < img.height) img.at(x, y) = linear(display);
  }
  void line(double x0, double y0, double x1, double y1, pt::Vec3 c, int thick = 1, bool dashed = false) {
    double len = std::hypot(x1 - x0, y1 - y0);
    int steps = std::max(1, int(len * 2));
    for (int i = 0; i <= steps; ++i) {
      double t = double(i) / steps;
      if (dashed && int(t * len / 6) % 2) continue;
      int x = int(std::lround(x0 + (x1 - x0) * t)), y = int(std::lround(y0 + (y1 - y0) * t));
      for (int dy = 0; dy < thick; ++dy)
        for (int dx = 0; dx < thick; ++dx) set(x + dx - thick / 2, y + dy - thick / 2, c);
    }
  }
  // Text with its top-left corner at (x, y), each font pixel `scale` pixels square.
  void text(int x, int y, const std::string& s, pt::Vec3 c = {0, 0, 0}, int scale = 2) {
    for (char ch : s) {
      const unsigned char* g = plot_detail::glyph(ch);
      for (int r = 0; r < 5; ++r)
        for (int col = 0; col < 3; ++col)
          if (g[r] & (4 >> col))
            for (int sy = 0; sy < scale; ++sy)
              for (int sx = 0; sx < scale; ++sx) set(x + col * scale + sx, y + r * scale + sy, c);
      x += 4 * scale;
    }
  }
  static int text_width(const std::string& s, int scale = 2) { return int(s.size()) * 4 * scale - scale; }

  pt::ImageRGB img;
};

inline std::string decade_label(int k) {
  if (k >= -2 && k <= 3) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%g", std::pow(10.0, k));
    return buf;
  }
  return "1E" + std::to_string(k);
}

// Log-log plot of the series (non-positive and non-finite values are skipped) with decade grid lines.
inline pt::ImageRGB loglog_plot(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                                const std::vector<Series>& series, int w = 720, int h = 480) {
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  for (const Series& s : series)
    for (size_t i = 0; i < s.x.size(); ++i)
      if (s.x[i] > 0 && s.y[i] > 0 && std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        xmin = std::min(xmin, s.x[i]);
        xmax = std::max(xmax, s.x[i]);
        ymin = std::min(ymin, s.y[i]);
        ymax = std::max(ymax, s.y[i]);
      }
  if (!(xmin <= xmax)) xmin = 1, xmax = 10;
  if (!(ymin <= ymax)) ymin = 1, ymax = 10;
  // A point within 5% of a decade line gets the next decade too, so nothing sits on an axis.
  int dx0 = int(std::floor(std::log10(xmin) - 0.05)), dx1 = std::max(dx0 + 1, int(std::ceil(std::log10(xmax) + 0.05)));
  int dy0 = int(std::floor(std::log10(ymin) - 0.05)), dy1 = std::max(dy0 + 1, int(std::ceil(std::log10(ymax) + 0.05)));
  const int left = 80, right = 24, top = 60, bottom = 56;
  const int pw = w - left - right, ph = h - top - bottom;
  auto px = [&](double x) { return left + (std::log10(x) - dx0) / (dx1 - dx0) * pw; };
  auto py = [&](double y) { return top + ph - (std::log10(y) - dy0) / (dy1 - dy0) * ph; };

  Canvas c(w, h);
  const pt::Vec3 minor(0.93f, 0.93f, 0.93f), major(0.78f, 0.78f, 0.78f), black(0, 0, 0);
  for (int k = dx0; k < dx1; ++k)
    for (int m = 2; m <= 9; ++m) c.line(px(m * std::pow(10.0, k)), top, px(m * std::pow(10.0, k)), top + ph, minor);
  for (int k = dy0; k < dy1; ++k)
    for (int m = 2; m <= 9; ++m) c.line(left, py(m * std::pow(10.0, k)), left + pw, py(m * std::pow(10.0, k)), minor);
  for (int k = dx0; k <= dx1; ++k) {
    double x = px(std::pow(10.0, k));
    c.line(x, top, x, top + ph, major);
    std::string l = decade_label(k);
    c.text(int(x) - Canvas::text_width(l) / 2, top + ph + 8, l);
  }
  for (int k = dy0; k <= dy1; ++k) {
    double y = py(std::pow(10.0, k));
    c.line(left, y, left + pw, y, major);
    std::string l = decade_label(k);
    c.text(left - 8 - Canvas::text_width(l), int(y) - 5, l);
  }
  c.line(left, top, left, top + ph, black, 2);
  c.line(left, top + ph, left + pw, top + ph, black, 2);
  c.text(8, 10, title, black, 2);
  c.text(left + pw - Canvas::text_width(xlabel), h - 22, xlabel);
  c.text(8, top - 30, ylabel);

  int ly = top + 10;
  for (const Series& s : series) {
    std::vector<std::pair<double, double>> pts;
    for (size_t i = 0; i < s.x.size(); ++i)
      if (s.x[i] > 0 && s.y[i] > 0 && std::isfinite(s.x[i]) && std::isfinite(s.y[i])) pts.push_back({px(s.x[i]), py(s.y[i])});
    for (size_t i = 1; i < pts.size(); ++i)
      c.line(pts[i - 1].first, pts[i - 1].second, pts[i].first, pts[i].second, s.colour, 2, s.dashed);
    if (!s.dashed)
      for (auto& p : pts)
        for (int d = -3; d <= 3; ++d) {
          c.set(int(p.first) + d, int(p.second), s.colour);
          c.set(int(p.first), int(p.second) + d, s.colour);
        }
    // Legend, top right.
    int lx = left + pw - 250;
    c.line(lx, ly + 5, lx + 30, ly + 5, s.colour, 2, s.dashed);
    c.text(lx + 40, ly, s.label, black);
    ly += 18;
  }
  return c.img;
}

}  // namespace bench
