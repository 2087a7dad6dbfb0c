// The GLFW debug window, run for real under Xvfb (Mesa's llvmpipe) and driven by --script: the
// framebuffer shows the same image as the CLI render, keys change the settings they name, a
// click focuses on the surface under it, S / D write into the current directory or --output-dir,
// resizing re-renders at the window size, and restarting or closing never waits for a long pass.
// The overlay's own tests: test_viewer_overlay.cpp.
#include <OpenImageIO/imageio.h>

#include <regex>

#include "cli.h"
#include "collada.h"
#include "denoiser.h"
#include "session.h"
#include "viewer_harness.h"

using namespace pt;
using namespace viewer_test;

namespace {

// Mean absolute difference in 8-bit levels; sizes must match.
double mean_abs_diff_levels(const std::string& a, const std::string& b) {
  ImageRGB x = read_image(a), y = read_image(b);
  EXPECT_EQ(x.width, y.width);
  EXPECT_EQ(x.height, y.height);
  if (x.width != y.width || x.height != y.height) return 1e9;
  double sum = 0;
  for (size_t i = 0; i < x.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) sum += std::abs(x.pixels[i][c] - y.pixels[i][c]) * 255.0;
  return sum / (3.0 * x.pixels.size());
}


}  // namespace

TEST(ViewerCli, HelpListsTheWindowKeys) {
  RunResult r = run("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.output.find("Window keys"), std::string::npos);
  for (const char* k : {"R ", ". / ,", "L / K", "' / ;", "] / [", "= / -", "T ", "S ", "D ", "click", "H (or `)", "? (/)",
                        "Esc / Q", "--output-dir"})
    EXPECT_NE(r.output.find(k), std::string::npos) << k;
}

// The script player is the test build's (pathtracer-scripted): the shipped command does not know it.
TEST(ViewerCli, TheShippedCommandHasNoScriptPlayer) {
  test::RunResult r = test::run_command(std::string(PT_PATHTRACER) + " --script x.txt " + test::own_scene("cornell.dae"));
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("unknown option '--script'"), std::string::npos) << r.output;
  EXPECT_EQ(test::run_command(std::string(PT_PATHTRACER) + " --help").output.find("--script"), std::string::npos);
}

TEST(ViewerCli, WithoutADisplayExitsWith2AndSaysSo) {
  RunResult r = run(test::own_scene("cornell.dae"), "env -u DISPLAY -u WAYLAND_DISPLAY");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("-f FILE"), std::string::npos) << r.output;
}

TEST(ViewerCli, AMissingOutputDirIsRefusedBeforeTheWindowOpens) {
  RunResult r = run("--output-dir /nonexistent/shots " + test::own_scene("cornell.dae"), "env -u DISPLAY");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("--output-dir /nonexistent/shots: not a directory"), std::string::npos) << r.output;
}

TEST(ViewerCli, BadScriptIsNamedByLine) {
  std::string path = test::temp_dir() + "/bad_script.txt";
  std::ofstream(path) << "wait_spp 1\n\nkey F1\n";
  RunResult r = run("--script " + path + " " + test::own_scene("cornell.dae"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("bad_script.txt:3"), std::string::npos) << r.output;
}

TEST_F(Viewer, FramebufferMatchesTheCliRender) {
  const std::string flags = "-t 2 -s 64 -m 3 -r 120 90 --seed 3";
  RunResult w = run_window(flags, "key `\nwait_spp 64\nscreenshot " + m_dir + "/window.png\nkey T\nscreenshot " +
                                      m_dir + "/window_rate.png\nquit\n");
  RunResult c = run(flags + " --quiet -f " + m_dir + "/cli.png " + m_scene);
  ASSERT_EQ(c.status, 0) << c.output;
  double d = mean_abs_diff_levels(m_dir + "/window.png", m_dir + "/cli.png");
  EXPECT_LT(d, 0.5) << "mean absolute difference in 8-bit levels";
  // The sample-rate view shows the CLI's _rate.png (adaptive sampling stops some pixels early).
  EXPECT_LT(mean_abs_diff_levels(m_dir + "/window_rate.png", m_dir + "/cli_rate.png"), 0.5);
  std::printf("window vs CLI: %.4f levels; window run %.2f s\n", d, w.seconds);
}

// --target-error ends the window's render as it ends a file render: the pass that reaches it is
// the last, well short of the sample budget, and the title says the render is done.
TEST_F(Viewer, TheErrorTargetEndsTheRender) {
  RunResult r = run_window("-t 2 -s 65536 -m 3 -r 64 48 --target-error 0.01", "wait_spp 65536\ntitle\nquit\n");
  const std::string& o = r.output;
  const std::string pass = last_line_with(o, "pass: ");
  EXPECT_NE(pass.find("error target reached"), std::string::npos) << o;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(pass, m, std::regex(R"(pass: (\d+)/65536 spp, error estimate ([0-9.e+-]+))"))) << pass;
  EXPECT_LT(std::stoi(m[1]), 65536) << pass;
  EXPECT_LE(std::stod(m[2]), 0.01) << pass;
  const std::string title = last_line_with(o, "title: ");
  EXPECT_NE(title.find("spp " + std::string(m[1]) + "/65536 done"), std::string::npos) << title;
}

// --time-limit ends the window's render as it ends a file render (the same driver): the pass it
// cuts short is the last, the title says done, and the budget is far from spent.
TEST_F(Viewer, TheTimeLimitEndsTheRender) {
  RunResult r = run_window("-t 2 -s 65536 -m 3 -r 64 48 --no-adaptive --time-limit 0.5", "wait_spp 65536\ntitle\nquit\n");
  const std::string& o = r.output;
  const std::string pass = last_line_with(o, "pass: ");
  EXPECT_NE(pass.find("time limit reached"), std::string::npos) << o;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(pass, m, std::regex(R"(pass: (\d+)/65536 spp)"))) << pass;
  EXPECT_LT(std::stoi(m[1]), 65536) << pass;
  const std::string title = last_line_with(o, "title: ");
  EXPECT_NE(title.find("spp " + std::string(m[1]) + "/65536 done"), std::string::npos) << title;
}

TEST_F(Viewer, KeysChangeTheSettingsTheyName) {
  RunResult r = run_window("-t 2 -s 4 -m 3 -r 160 120 --output-dir " + m_dir, R"(wait_spp 1
key .
key L
key '
key ]
key =
overlay
wait_spp 8
key S
sync
key ,
key K
key ;
key [
key -
overlay
key R
key T
key ?
quit
)");
  const std::string& o = r.output;
  for (const char* line : {"max depth 4", "lens radius 0.05", "focal distance 4.8", "spp 8", "light samples 2",
                           "max depth 3", "lens radius 0", "focal distance 4.7", "spp 4", "light samples 1", "restart",
                           "view: sample rate", "Window keys:"})
    EXPECT_NE(o.find(std::string("\n") + line + "\n"), std::string::npos) << line << "\n" << o;
  // The panel shows the settings.
  std::string first = o.substr(o.find("overlay: "));
  first = first.substr(0, first.find('\n'));
  EXPECT_NE(first.find("max depth 4 | lens radius 0.05 | focal dist 4.8 | light samples 2"), std::string::npos) << o;
  std::string last = last_line_with(o, "overlay: ");
  EXPECT_NE(last.find("max depth 3 | lens radius 0 | focal dist 4.7 | light samples 1"), std::string::npos) << last;
  // The saved render was made with the changed settings (its EXR header says so).
  std::string exr;
  for (const std::string& f : files_in(m_dir))
    if (ends_with(f, ".exr")) exr = m_dir + "/" + f;
  ASSERT_FALSE(exr.empty()) << o;
  auto in = OIIO::ImageInput::open(exr);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().get_string_attribute("pathtracer:max_depth"), "4");
  EXPECT_EQ(in->spec().get_string_attribute("pathtracer:lens_radius"), "0.05");
  EXPECT_EQ(in->spec().get_string_attribute("pathtracer:spp"), "8");
  EXPECT_EQ(in->spec().get_string_attribute("pathtracer:light_samples"), "2");
  EXPECT_EQ(in->spec().get_string_attribute("pathtracer:achieved_spp"), "8");
}

TEST_F(Viewer, ClickFocusesOnTheSurfaceUnderIt) {
  RunResult r = run_window("-t 2 -s 2 -b 0.1 -r 120 90", "wait_spp 1\nclick 30 70\nsync\nwait_spp 2\noverlay\nquit\n");
  RenderParams p;
  p.width = 120;
  p.height = 90;
  p.lens_radius = 0.1f;
  auto scene = make_render_scene(load_collada(m_scene), p);
  float expect = autofocus_distance(*scene, 30.0f / 120, 1 - 70.0f / 90);
  ASSERT_TRUE(std::isfinite(expect));
  EXPECT_NE(expect, 4.7f);
  double shown = value_after(last_line_with(r.output, "overlay: "), "| focal dist ");
  EXPECT_NEAR(shown, expect, 1e-5 * expect) << r.output;
  EXPECT_NEAR(value_after(r.output, "focal distance "), expect, 1e-5 * expect) << r.output;
}

namespace {

// The files S and D wrote into `dir`: screenshot PNG, rate PNG, EXR and camera settings counts.
struct Written {
  int png = 0, rate = 0, exr = 0, cam = 0;
};
Written written_in(const std::string& dir) {
  Written w;
  for (const std::string& f : files_in(dir)) {
    if (f == "cornell_cam_settings.txt") ++w.cam;
    if (f.rfind("cornell_screenshot_", 0) != 0) continue;
    if (ends_with(f, "_rate.png")) ++w.rate;
    else if (ends_with(f, ".png")) ++w.png;
    else if (ends_with(f, ".exr")) ++w.exr;
  }
  return w;
}

}  // namespace

// S and D write into the current directory, never next to the scene (its folder may be shared or
// read-only), and the log names what was written.
TEST_F(Viewer, SaveAndCameraKeysWriteToTheCurrentDirectory) {
  const std::string cwd = m_dir + "/cwd";
  mkdir(cwd.c_str(), 0755);
  for (const std::string& f : files_in(cwd)) unlink((cwd + "/" + f).c_str());
  RunResult r = run_window("-t 2 -s 4 -r 64 48", "key L\nwait_spp 4\nkey S\nkey D\nsync\nquit\n", cwd);
  Written here = written_in(cwd), beside = written_in(m_dir);
  EXPECT_EQ(here.png, 1) << r.output;
  EXPECT_EQ(here.rate, 1) << r.output;
  EXPECT_EQ(here.exr, 1) << r.output;
  EXPECT_EQ(here.cam, 1) << r.output;
  EXPECT_EQ(beside.png + beside.rate + beside.exr + beside.cam, 0) << "written next to the scene: " << r.output;
  std::smatch m;
  std::string saved = last_line_with(r.output, "saved ");
  ASSERT_TRUE(std::regex_search(saved, m, std::regex(R"(saved (\S+\.png),)"))) << r.output;
  EXPECT_EQ(access((cwd + "/" + std::string(m[1])).c_str(), F_OK), 0) << saved;
  std::ifstream cam(cwd + "/cornell_cam_settings.txt");
  ASSERT_TRUE(cam) << r.output;
  std::vector<std::string> lines;
  for (std::string l; std::getline(cam, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[5], "4.7 0.05");  // focal distance, lens radius: as shown in the window
}

TEST_F(Viewer, OutputDirTakesTheSavedFiles) {
  const std::string out = m_dir + "/shots", cwd = m_dir + "/cwd";
  for (const std::string& d : {out, cwd}) {
    mkdir(d.c_str(), 0755);
    for (const std::string& f : files_in(d)) unlink((d + "/" + f).c_str());
  }
  RunResult r = run_window("-t 2 -s 4 -r 64 48 --output-dir " + out, "wait_spp 4\nkey S\nkey D\nsync\nquit\n", cwd);
  Written there = written_in(out), here = written_in(cwd), beside = written_in(m_dir);
  EXPECT_EQ(there.png + there.rate + there.exr + there.cam, 4) << r.output;
  EXPECT_EQ(here.png + here.rate + here.exr + here.cam, 0) << r.output;
  EXPECT_EQ(beside.png + beside.rate + beside.exr + beside.cam, 0) << r.output;
  EXPECT_NE(last_line_with(r.output, "saved ").find("saved " + out + "/cornell_screenshot_"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("wrote " + out + "/cornell_cam_settings.txt"), std::string::npos) << r.output;
}

TEST_F(Viewer, ResizingRendersAtTheNewFramebufferSize) {
  RunResult r = run_window("-t 2 -s 4 -r 96 72 --seed 1",
                           "key `\nwait_spp 4\nresize 64 48\nwait_spp 4\nscreenshot " + m_dir + "/small.png\nquit\n");
  EXPECT_NE(r.output.find("size 64x48"), std::string::npos) << r.output;
  RunResult c = run("-t 2 -s 4 -r 64 48 --seed 1 --quiet -f " + m_dir + "/cli.png " + m_scene);
  ASSERT_EQ(c.status, 0) << c.output;
  EXPECT_LT(mean_abs_diff_levels(m_dir + "/small.png", m_dir + "/cli.png"), 0.5);
}

// 4096 light samples a vertex at 400x300, depth 8: the first pass (one sample a pixel) is billions
// of shadow rays, many seconds on any machine, while each 8x8 tile is a fraction of one, so the
// cancel flag is seen soon. A restart ("sync" answers once the new session runs) and a close with
// a clean exit and no pass ever completed show that both cancel the running pass rather than wait
// for it: a restart that waited would print the pass's "pass:" line first. No clock is read.
TEST_F(Viewer, RestartAndCloseDoNotWaitForTheRunningPass) {
  RunResult r = run_window("-t 2 -s 1000000 -l 4096 -m 8 -r 400 300 --tile 8", "wait_ms 300\nkey .\nsync\nwait_ms 300\nclose\n");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("sync: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("max depth 9"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("pass: "), std::string::npos) << "a pass ended instead of being cancelled: " << r.output;
  std::printf("restart took %.0f ms; whole run %.2f s\n", value_after(r.output, "sync: "), r.seconds);
}

// Lowering the depth until the scene's mirror and glass go dark, then black, says why once each,
// as the CLI's hints do; going back and forth does not repeat it.
TEST_F(Viewer, ADepthThatBlacksOutMirrorsSaysWhyOnce) {
  RunResult r = run_window("-t 2 -s 1 -m 3 -r 64 48", "wait_spp 1\nkey ,\nkey ,\nkey .\nkey ,\nsync\nquit\n");
  auto count = [&](const std::string& s) {
    size_t n = 0;
    for (size_t at = 0; (at = r.output.find(s, at)) != std::string::npos; ++at) ++n;
    return n;
  };
  EXPECT_EQ(count("hint: -m 2 leaves mirror and glass dark"), 1u) << r.output;
  EXPECT_EQ(count("hint: -m 1 leaves mirror and glass black"), 1u) << r.output;
}

// N shows the film denoised at pass ends (restarting once to gather the denoiser's features), and
// the denoised picture is smoother than the raw one the same render shows after N again.
TEST_F(Viewer, NShowsTheDenoisedFilm) {
  if (!Denoiser::shared().available()) {
    if (test::under_ci()) FAIL() << "under CI=true the denoiser must be installed: " << Denoiser::shared().description();
    GTEST_SKIP() << Denoiser::shared().description();
  }
  RunResult r = run_window("-t 2 -s 16 -m 3 -r 120 90 --seed 3 --no-adaptive",
                           "key `\nkey N\nwait_spp 16\nsync\nscreenshot " + m_dir + "/denoised.png\nkey N\nsync\nscreenshot " +
                               m_dir + "/raw.png\nquit\n");
  const std::string& o = r.output;
  EXPECT_NE(o.find("view: denoised (the render restarts"), std::string::npos) << o;
  EXPECT_NE(o.find("denoised: 16 spp in"), std::string::npos) << o;
  EXPECT_NE(o.find("view: radiance"), std::string::npos) << o;
  auto roughness = [](const std::string& path) {  // squared differences of horizontal neighbours
    const ImageRGB img = read_image(path);
    double sum = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x + 1 < img.width; ++x) {
        const float d = luminance(img.at(x + 1, y)) - luminance(img.at(x, y));
        sum += double(d) * d;
      }
    return sum;
  };
  const double denoised = roughness(m_dir + "/denoised.png"), raw = roughness(m_dir + "/raw.png");
  EXPECT_LT(denoised, 0.7 * raw) << "denoised " << denoised << ", raw " << raw;
}
