// The GLFW debug window, run for real under Xvfb (Mesa's llvmpipe) and driven by --script: the
// framebuffer shows the same image as the CLI render, keys change the settings they name, a
// click focuses on the surface under it, S / D write next to the scene, resizing re-renders at
// the window size, and restarting or closing never waits for a long pass.
#include <gtest/gtest.h>

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include "cli.h"
#include "collada.h"
#include "session.h"
#include "test_util.h"

using namespace pt;

namespace {

struct RunResult {
  int status;
  std::string output;
  double seconds;
};

RunResult run(const std::string& args, const std::string& env = "") {
  std::string cmd = env + " timeout 120 " + std::string(PT_PATHTRACER) + " " + args + " 2>&1";
  auto t0 = std::chrono::steady_clock::now();
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  int st = pclose(p);
  double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out, s};
}

bool on_path(const std::string& prog) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string d; std::getline(dirs, d, ':');)
    if (access((d + "/" + prog).c_str(), X_OK) == 0) return true;
  return false;
}

std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) if (e->d_type != DT_DIR) names.push_back(e->d_name);
    closedir(d);
  }
  return names;
}

// An Xvfb server for this test process; -displayfd lets it pick a free display itself, so tests
// running in parallel never race for one.
class Xvfb {
 public:
  ~Xvfb() {
    if (m_pid > 0) {
      kill(m_pid, SIGTERM);
      waitpid(m_pid, nullptr, 0);
    }
  }
  // Returns "" on success, else why not.
  std::string start() {
    int fds[2];
    if (pipe(fds) != 0) return "pipe failed";
    m_pid = fork();
    if (m_pid == 0) {
      close(fds[0]);
      int devnull = open("/dev/null", O_WRONLY);
      dup2(devnull, 1);
      dup2(devnull, 2);
      std::string fd = std::to_string(fds[1]);
      execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "640x480x24", "-nolisten", "tcp", nullptr);
      _exit(127);
    }
    close(fds[1]);
    std::string number;
    pollfd pfd{fds[0], POLLIN, 0};
    while (poll(&pfd, 1, 20000) > 0) {
      char c;
      if (read(fds[0], &c, 1) != 1 || c == '\n') break;
      number += c;
    }
    close(fds[0]);
    if (number.empty()) return "Xvfb did not report a display";
    m_display = ":" + number;
    return "";
  }
  const std::string& display() const { return m_display; }

 private:
  pid_t m_pid = -1;
  std::string m_display;
};

class Viewer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!on_path("Xvfb")) return;
    s_xvfb = new Xvfb;
    s_error = s_xvfb->start();
    if (s_error.empty()) setenv("DISPLAY", s_xvfb->display().c_str(), 1);
  }
  static void TearDownTestSuite() {
    delete s_xvfb;
    s_xvfb = nullptr;
  }
  void SetUp() override {
    if (!s_xvfb) GTEST_SKIP() << "Xvfb is not installed (package xvfb)";
    ASSERT_EQ(s_error, "") << "cannot start Xvfb";
    m_dir = test::temp_dir() + "/viewer_" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
    mkdir(m_dir.c_str(), 0755);
    for (const std::string& f : files_in(m_dir)) unlink((m_dir + "/" + f).c_str());  // earlier runs' files
    // The scene is copied so that S and D write next to it in a directory of our own.
    m_scene = m_dir + "/cornell.dae";
    std::ifstream in(test::own_scene("cornell.dae"));
    std::ofstream(m_scene) << in.rdbuf();
  }

  // Runs the window with a script; fails the test unless it exits with status 0.
  RunResult run_window(const std::string& flags, const std::string& script) {
    std::string path = m_dir + "/script.txt";
    std::ofstream(path) << script;
    RunResult r = run(flags + " --script " + path + " " + m_scene);
    EXPECT_EQ(r.status, 0) << r.output;
    return r;
  }

  static Xvfb* s_xvfb;
  static std::string s_error;
  std::string m_dir, m_scene;
};

Xvfb* Viewer::s_xvfb = nullptr;
std::string Viewer::s_error;

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

// The value after `key` on the last line that has it ("focus 4.8 |" -> 4.8).
double value_after(const std::string& out, const std::string& key) {
  size_t at = out.rfind(key);
  if (at == std::string::npos) return NAN;
  return std::strtod(out.c_str() + at + key.size(), nullptr);
}

std::string last_line_with(const std::string& out, const std::string& prefix) {
  std::istringstream in(out);
  std::string found;
  for (std::string l; std::getline(in, l);)
    if (l.rfind(prefix, 0) == 0) found = l;
  return found;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

TEST(ViewerCli, HelpListsTheWindowKeys) {
  RunResult r = run("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.output.find("Window keys"), std::string::npos);
  for (const char* k : {"R ", ". / ,", "L / K", "' / ;", "] / [", "= / -", "T ", "S ", "D ", "click", "H ", "Esc / Q",
                        "--script"})
    EXPECT_NE(r.output.find(k), std::string::npos) << k;
}

TEST(ViewerCli, WithoutADisplayExitsWith2AndSaysSo) {
  RunResult r = run(test::own_scene("cornell.dae"), "env -u DISPLAY -u WAYLAND_DISPLAY");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("-f FILE"), std::string::npos) << r.output;
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
  RunResult w = run_window(flags, "wait_spp 64\nscreenshot " + m_dir + "/window.png\nkey T\nscreenshot " + m_dir +
                                      "/window_rate.png\nquit\n");
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
  EXPECT_NE(title.find(std::string(m[1]) + "/65536 spp done"), std::string::npos) << title;
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
  EXPECT_NE(title.find(std::string(m[1]) + "/65536 spp done"), std::string::npos) << title;
}

TEST_F(Viewer, KeysChangeTheSettingsTheyName) {
  RunResult r = run_window("-t 2 -s 4 -m 3 -r 64 48", R"(wait_spp 1
key .
key L
key '
key ]
key =
title
wait_spp 8
key S
sync
key ,
key K
key ;
key [
key -
title
key R
key T
key H
quit
)");
  const std::string& o = r.output;
  for (const char* line : {"max depth 4", "lens radius 0.05", "focal distance 4.8", "spp 8", "light samples 2",
                           "max depth 3", "lens radius 0", "focal distance 4.7", "spp 4", "light samples 1", "restart",
                           "view: sample rate", "Window keys:"})
    EXPECT_NE(o.find(std::string("\n") + line + "\n"), std::string::npos) << line << "\n" << o;
  std::string first = o.substr(o.find("title: "));
  EXPECT_NE(first.find("depth 4 | lens 0.05 | focus 4.8 | light 2"), std::string::npos) << first;
  std::string last = last_line_with(o, "title: ");
  EXPECT_NE(last.find("depth 3 | lens 0 | focus 4.7 | light 1"), std::string::npos) << last;
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
  RunResult r = run_window("-t 2 -s 2 -b 0.1 -r 120 90", "wait_spp 1\nclick 30 70\nsync\nwait_spp 2\ntitle\nquit\n");
  RenderParams p;
  p.width = 120;
  p.height = 90;
  p.lens_radius = 0.1f;
  auto scene = make_render_scene(load_collada(m_scene), p);
  float expect = autofocus_distance(*scene, 30.0f / 120, 1 - 70.0f / 90);
  ASSERT_TRUE(std::isfinite(expect));
  EXPECT_NE(expect, 4.7f);
  double shown = value_after(last_line_with(r.output, "title: "), "| focus ");
  EXPECT_NEAR(shown, expect, 1e-5 * expect) << r.output;
  EXPECT_NEAR(value_after(r.output, "focal distance "), expect, 1e-5 * expect) << r.output;
}

TEST_F(Viewer, SaveAndCameraKeysWriteNextToTheScene) {
  RunResult r = run_window("-t 2 -s 4 -r 64 48", "key L\nwait_spp 4\nkey S\nkey D\nsync\nquit\n");
  int png = 0, rate = 0, exr = 0;
  for (const std::string& f : files_in(m_dir)) {
    if (f.rfind("cornell_screenshot_", 0) != 0) continue;
    if (ends_with(f, "_rate.png")) ++rate;
    else if (ends_with(f, ".png")) ++png;
    else if (ends_with(f, ".exr")) ++exr;
  }
  EXPECT_EQ(png, 1) << r.output;
  EXPECT_EQ(rate, 1) << r.output;
  EXPECT_EQ(exr, 1) << r.output;
  std::ifstream cam(m_dir + "/cornell_cam_settings.txt");
  ASSERT_TRUE(cam) << r.output;
  std::vector<std::string> lines;
  for (std::string l; std::getline(cam, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[5], "4.7 0.05");  // focal distance, lens radius: as shown in the window
}

TEST_F(Viewer, ResizingRendersAtTheNewFramebufferSize) {
  RunResult r = run_window("-t 2 -s 4 -r 96 72 --seed 1",
                           "wait_spp 4\nresize 64 48\nwait_spp 4\nscreenshot " + m_dir + "/small.png\nquit\n");
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
