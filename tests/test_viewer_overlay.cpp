// The debug window's overlay under Xvfb, read back from the framebuffer (the script's
// screenshot): the status panel draws its text pixel for pixel in the bitmap font and ` toggles
// it through the window's key handler; it stays inside the smallest window, keeps its status
// lines there, and grows with the framebuffer; the sample-rate view draws a colour legend.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <regex>

#include "bitmap_font.h"
#include "cli.h"
#include "viewer_harness.h"

using namespace pt;
using namespace viewer_test;

namespace {

// A screenshot's 8-bit RGB levels, top row first.
struct Rgb8 {
  int w = 0, h = 0;
  std::vector<uint8_t> px;
  const uint8_t* at(int x, int y) const { return &px[(size_t(y) * w + x) * 3]; }
  bool white(int x, int y) const { return at(x, y)[0] == 255 && at(x, y)[1] == 255 && at(x, y)[2] == 255; }
};
Rgb8 read_rgb8(const std::string& path) {
  Rgb8 img;
  auto in = OIIO::ImageInput::open(path);
  if (!in) return img;
  img.w = in->spec().width;
  img.h = in->spec().height;
  img.px.resize(size_t(img.w) * img.h * 3);
  if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, img.px.data())) img.px.clear();
  return img;
}

struct Box {
  int x = 0, y = 0, w = 0, h = 0;
  bool contains(int px, int py) const { return px >= x && px < x + w && py >= y && py < y + h; }
  bool inside(int fw, int fh) const { return x >= 0 && y >= 0 && w > 0 && h > 0 && x + w <= fw && y + h <= fh; }
};

// What one "overlay" script command reported (the window's log line).
struct OverlayReport {
  bool panel = false, legend = false;
  Box rect, legend_rect, bar;
  int fw = 0, fh = 0, scale = 0;
  std::string samples;  // the legend's "lo..hi of spp"
  std::vector<std::string> lines;
};
OverlayReport parse_overlay(const std::string& line) {
  OverlayReport o;
  std::smatch m;
  if (std::regex_search(line, m, std::regex(R"(framebuffer (\d+)x(\d+))"))) o.fw = std::stoi(m[1]), o.fh = std::stoi(m[2]);
  if ((o.panel = std::regex_search(line, m, std::regex(R"(\| panel (\d+) (\d+) (\d+) (\d+) scale (\d+))")))) {
    o.rect = {std::stoi(m[1]), std::stoi(m[2]), std::stoi(m[3]), std::stoi(m[4])};
    o.scale = std::stoi(m[5]);
  }
  if ((o.legend = std::regex_search(
           line, m, std::regex(R"(\| legend (\d+) (\d+) (\d+) (\d+) bar (\d+) (\d+) (\d+) (\d+) samples ([^|]+?) \|)")))) {
    o.legend_rect = {std::stoi(m[1]), std::stoi(m[2]), std::stoi(m[3]), std::stoi(m[4])};
    o.bar = {std::stoi(m[5]), std::stoi(m[6]), std::stoi(m[7]), std::stoi(m[8])};
    o.samples = m[9];
  }
  // The panel's text: the fields after the layout ones.
  std::istringstream in(line);
  for (std::string f; std::getline(in, f, '|');) {
    f = f.substr(f.find_first_not_of(' '));
    f = f.substr(0, f.find_last_not_of(' ') + 1);
    if (f.rfind("overlay:", 0) != 0 && f.rfind("panel ", 0) != 0 && f.rfind("legend ", 0) != 0) o.lines.push_back(f);
  }
  return o;
}

// Whether the panel's first line is drawn pixel for pixel in the bitmap font at the panel's scale.
bool first_line_drawn(const Rgb8& img, const OverlayReport& o) {
  const int s = o.scale, x0 = o.rect.x + 2 * s, y0 = o.rect.y + 2 * s;
  const std::string& text = o.lines.at(0);
  for (size_t i = 0; i < text.size(); ++i)
    for (int gy = 0; gy < kGlyphH; ++gy)
      for (int gx = 0; gx < kGlyphW; ++gx) {
        int x = x0 + (int(i) * kCellW + gx) * s + s / 2, y = y0 + gy * s + s / 2;
        if (x >= o.rect.x + o.rect.w) return true;  // clipped at the panel's edge
        if (img.white(x, y) != glyph_lit(text[i], gx, gy)) return false;
      }
  return true;
}

}  // namespace

// The status panel draws legible text over the image, H hides and shows it again (through the
// window's own key handler, as a key press would; ` does the same), and ? lists the keys in it.
TEST_F(Viewer, ThePanelDrawsTextAndHTogglesIt) {
  RunResult r = run_window("-t 2 -s 4 -r 200 150", "wait_spp 4\noverlay\nscreenshot " + m_dir + "/shown.png\nkey H\n" +
                                                       "overlay\nscreenshot " + m_dir + "/hidden.png\nkey `\n" +
                                                       "screenshot " + m_dir + "/again.png\nkey H\nkey ?\n" +
                                                       "overlay\nquit\n");
  std::istringstream log(r.output);
  std::vector<OverlayReport> reports;
  for (std::string l; std::getline(log, l);)
    if (l.rfind("overlay: ", 0) == 0) reports.push_back(parse_overlay(l));
  ASSERT_EQ(reports.size(), 3u) << r.output;
  const OverlayReport& o = reports[0];
  ASSERT_TRUE(o.panel) << r.output;
  EXPECT_FALSE(reports[1].panel) << r.output;
  EXPECT_TRUE(o.rect.inside(200, 150)) << r.output;
  ASSERT_GE(o.lines.size(), 8u) << r.output;
  EXPECT_EQ(o.lines[0], "spp 4/4 done");
  EXPECT_EQ(o.lines[1].rfind("error ", 0), 0u) << o.lines[1];
  EXPECT_EQ(o.lines[2].rfind("took ", 0), 0u) << o.lines[2];
  EXPECT_EQ(o.lines[7], "view radiance");

  Rgb8 shown = read_rgb8(m_dir + "/shown.png"), hidden = read_rgb8(m_dir + "/hidden.png"),
       again = read_rgb8(m_dir + "/again.png");
  ASSERT_EQ(shown.w, 200);
  ASSERT_EQ(hidden.px.size(), shown.px.size());
  int changed_inside = 0, changed_outside = 0, white = 0;
  for (int y = 0; y < shown.h; ++y)
    for (int x = 0; x < shown.w; ++x) {
      bool changed = !std::equal(shown.at(x, y), shown.at(x, y) + 3, hidden.at(x, y));
      if (o.rect.contains(x, y)) {
        changed_inside += changed;
        white += shown.white(x, y);
      } else {
        changed_outside += changed;
      }
    }
  EXPECT_EQ(changed_outside, 0);
  EXPECT_GT(white, 300) << "text pixels";
  EXPECT_GE(changed_inside, white) << "the panel changes the image under it";
  EXPECT_TRUE(first_line_drawn(shown, o)) << o.lines[0];
  EXPECT_EQ(again.px, shown.px) << "` shows the same panel again";
  EXPECT_NE(r.output.find("panel: hidden"), std::string::npos);
  EXPECT_NE(r.output.find("panel: shown"), std::string::npos);
  // ? shows the keys in the panel even while H hides it.
  const OverlayReport& keys = reports[2];
  ASSERT_TRUE(keys.panel) << r.output;
  ASSERT_FALSE(keys.lines.empty());
  EXPECT_EQ(keys.lines[0].rfind("R ", 0), 0u) << keys.lines[0];
  EXPECT_NE(std::find_if(keys.lines.begin(), keys.lines.end(), [](const std::string& l) { return l[0] == 'H'; }),
            keys.lines.end());
}

// At the smallest window the window allows (160x120, unless -r asks for less) the panel shows every
// line at its smallest text, also above the rate legend; a smaller -r window keeps the first lines;
// a larger framebuffer gets larger text. The panel and legend always stay inside the framebuffer.
TEST_F(Viewer, ThePanelFitsSmallWindowsAndScalesWithLargeOnes) {
  struct Case {
    int w, h;
  };
  for (Case c : {Case{160, 120}, Case{64, 48}, Case{800, 600}}) {
    SCOPED_TRACE(std::to_string(c.w) + "x" + std::to_string(c.h));
    const std::string size = std::to_string(c.w) + " " + std::to_string(c.h), shot = m_dir + "/fit.png";
    RunResult r = run_window("-t 2 -s 1 -r " + size, "wait_spp 1\noverlay\nscreenshot " + shot + "\nkey T\noverlay\nquit\n");
    std::istringstream log(r.output);
    std::vector<OverlayReport> reports;
    for (std::string l; std::getline(log, l);)
      if (l.rfind("overlay: ", 0) == 0) reports.push_back(parse_overlay(l));
    ASSERT_EQ(reports.size(), 2u) << r.output;
    const OverlayReport &o = reports[0], &rate = reports[1];
    ASSERT_TRUE(o.panel && rate.panel && rate.legend) << r.output;
    EXPECT_EQ(o.fw, c.w);
    EXPECT_TRUE(o.rect.inside(c.w, c.h)) << r.output;
    EXPECT_TRUE(rate.rect.inside(c.w, c.h)) << r.output;
    EXPECT_TRUE(rate.legend_rect.inside(c.w, c.h)) << r.output;
    EXPECT_LE(rate.rect.y + rate.rect.h, rate.legend_rect.y) << "the panel overlaps the legend: " << r.output;
    EXPECT_EQ(o.lines.at(0), "spp 1/1 done");
    Rgb8 img = read_rgb8(shot);
    ASSERT_EQ(img.w, c.w);
    EXPECT_TRUE(first_line_drawn(img, o)) << r.output;
    if (c.w == 64) {
      EXPECT_EQ(o.scale, 1);
      continue;
    }
    EXPECT_EQ(o.scale, c.w == 800 ? 2 : 1) << r.output;
    EXPECT_EQ(o.lines.size(), 9u) << r.output;  // the status and the key hint, above the legend too
    EXPECT_EQ(rate.lines.size(), 9u) << r.output;
    EXPECT_EQ(rate.lines.at(7), "view sample rate") << r.output;
  }
}

// The sample-rate view draws a legend: the rate image's colours from 0 (blue) through spp / 2
// (green) to spp (red), the image's fewest and most samples in a pixel named and ticked.
TEST_F(Viewer, TheRateViewDrawsALegend) {
  RunResult r = run_window("-t 2 -s 8 --no-adaptive -r 200 150", "wait_spp 8\nkey T\noverlay\nscreenshot " + m_dir +
                                                                      "/rate.png\nkey `\nscreenshot " + m_dir +
                                                                      "/rate_clean.png\nquit\n");
  const OverlayReport o = parse_overlay(last_line_with(r.output, "overlay: "));
  ASSERT_TRUE(o.legend) << r.output;
  EXPECT_EQ(o.samples, "8..8 of 8");
  EXPECT_TRUE(o.legend_rect.inside(200, 150)) << r.output;
  ASSERT_GE(o.bar.w, 40) << r.output;
  Rgb8 img = read_rgb8(m_dir + "/rate.png"), clean = read_rgb8(m_dir + "/rate_clean.png");
  ASSERT_EQ(img.w, 200);
  ASSERT_EQ(clean.px.size(), img.px.size());
  auto rgb = [&](int x, int y) { return std::vector<int>(img.at(x, y), img.at(x, y) + 3); };
  const int mid = o.bar.y + o.bar.h / 2;
  EXPECT_EQ(rgb(o.bar.x + 1, mid), (std::vector<int>{0, 0, 255}));                     // 0 samples
  EXPECT_EQ(rgb(o.bar.x + (o.bar.w - 1) / 2, mid), (std::vector<int>{0, 255, 0}));     // 4
  EXPECT_EQ(rgb(o.bar.x + o.bar.w - 1 - 3 * o.scale, mid), (std::vector<int>{255, 0, 0}));  // 8
  EXPECT_TRUE(img.white(o.bar.x + o.bar.w - 1, o.bar.y - 1)) << "the tick at the image's 8 samples";
  // Without the overlay the rate view is the rate image alone (every pixel took 8 samples: red).
  EXPECT_EQ(std::vector<int>(clean.at(o.bar.x + 1, mid), clean.at(o.bar.x + 1, mid) + 3), (std::vector<int>{255, 0, 0}));
  int changed_outside = 0;
  for (int y = 0; y < img.h; ++y)
    for (int x = 0; x < img.w; ++x)
      if (!o.legend_rect.contains(x, y) && !o.rect.contains(x, y))
        changed_outside += !std::equal(img.at(x, y), img.at(x, y) + 3, clean.at(x, y));
  EXPECT_EQ(changed_outside, 0);
}

// ? lists every window key in a 320x240 window, each line whole (the panel's brief form), and the
// font's lower case sits below the capital line ("spp", not "sPP").
TEST_F(Viewer, TheKeyListFitsASmallWindowInLowerCase) {
  RunResult r = run_window("-t 2 -s 1 -r 320 240", "wait_spp 1\nkey ?\noverlay\nquit\n");
  const OverlayReport o = parse_overlay(last_line_with(r.output, "overlay: "));
  ASSERT_TRUE(o.panel) << r.output;
  EXPECT_EQ(o.lines.size(), window_keys().size()) << r.output;
  EXPECT_TRUE(o.rect.inside(320, 240)) << r.output;
  EXPECT_LE(o.rect.x + o.rect.w, 320 - o.rect.x) << "a line is clipped: " << r.output;
  for (char c : std::string("acegmnopqrsuvwxyz"))
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < kGlyphW; ++x) EXPECT_FALSE(glyph_lit(c, x, y)) << "'" << c << "' reaches row " << y;
}
