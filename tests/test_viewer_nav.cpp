// The window's camera moves (viewer_nav.h) driven through --script as a hand would drive them:
// a left drag orbits (a window height turns the polar angle by pi, a width the azimuth by pi), a
// right drag pans the target in the view plane, the wheel dollies by 1/20 of the initial distance,
// Space goes back; D writes the moved camera and -c renders the same image from it.
#include <cmath>
#include <fstream>
#include <sstream>

#include "image.h"
#include "viewer_harness.h"

using namespace pt;
using namespace viewer_test;

namespace {

// The course's camera settings file: line 2 position and target, line 3 phi theta distance.
struct Settings {
  double pos[3], target[3], phi, theta, dist, screen_distance;
};

Settings read_settings(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  Settings s{};
  EXPECT_EQ(lines.size(), 6u) << path;
  if (lines.size() != 6) return s;
  std::istringstream l2(lines[1]), l3(lines[2]), l5(lines[4]);
  l2 >> s.pos[0] >> s.pos[1] >> s.pos[2] >> s.target[0] >> s.target[1] >> s.target[2];
  l3 >> s.phi >> s.theta >> s.dist;
  double w, h;
  l5 >> w >> h >> s.screen_distance;
  return s;
}

double mean_abs_diff_levels(const std::string& a, const std::string& b) {
  ImageRGB x = read_image(a), y = read_image(b);
  if (x.width != y.width || x.height != y.height) return 1e9;
  double sum = 0;
  for (size_t i = 0; i < x.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) sum += std::abs(x.pixels[i][c] - y.pixels[i][c]) * 255.0;
  return sum / (3.0 * x.pixels.size());
}

double wrap_pi(double a) { return std::remainder(a, 2 * M_PI); }

}  // namespace

TEST_F(Viewer, DragsAndTheWheelMoveTheCameraAsTheCourseDoes) {
  const std::string flags = "-t 2 -s 16 -m 3 -r 120 90 --seed 3";
  const std::string cam = m_dir + "/cornell_cam_settings.txt";
  RunResult a = run_window(flags + " --output-dir " + m_dir, "wait_spp 1\nkey D\nsync\nquit\n");
  const Settings s0 = read_settings(cam);
  // Orbit: 20 px right on a 120-px-wide window turns the azimuth by -pi/6; 10 px down on 90 the
  // polar angle by -pi/9.
  RunResult b = run_window(flags + " --output-dir " + m_dir, "wait_spp 1\ndrag left 60 45 80 55 5\nwait_spp 16\nkey D\nsync\nquit\n");
  const Settings s1 = read_settings(cam);
  EXPECT_NEAR(wrap_pi(s1.theta - s0.theta), -M_PI / 6, 1e-3) << b.output;
  EXPECT_NEAR(s1.phi - s0.phi, -M_PI / 9, 1e-3);
  EXPECT_NEAR(s1.dist, s0.dist, 1e-4 * s0.dist);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s1.target[k], s0.target[k], 1e-5 * s0.dist);
  EXPECT_NE(b.output.find("camera: position"), std::string::npos) << b.output;
  // Pan: 10 px moves the target 10 pixels' worth at its depth, across the view; then two wheel
  // steps dolly in by 2/20 of the distance.
  RunResult c = run_window(flags + " --output-dir " + m_dir, "wait_spp 1\ndrag right 60 45 70 45 4\nwheel 2\nwait_spp 16\nkey D\nsync\nquit\n");
  const Settings s2 = read_settings(cam);
  double moved = 0, along = 0;
  for (int k = 0; k < 3; ++k) {
    moved += std::pow(s2.target[k] - s0.target[k], 2);
    along += (s2.target[k] - s0.target[k]) * (s0.pos[k] - s0.target[k]) / s0.dist;
  }
  EXPECT_NEAR(std::sqrt(moved), 10 * s0.dist / s0.screen_distance, 1e-3 * s0.dist) << c.output;
  EXPECT_NEAR(along, 0, 1e-4 * s0.dist) << "the pan moved the target along the view axis";
  EXPECT_NEAR(s2.dist, 0.9 * s0.dist, 1e-4 * s0.dist);
  // Space: back to the initial camera.
  run_window(flags + " --output-dir " + m_dir, "wait_spp 1\ndrag left 60 45 90 45 3\nkey Space\nwait_spp 1\nkey D\nsync\nquit\n");
  const Settings s3 = read_settings(cam);
  EXPECT_NEAR(s3.phi, s0.phi, 1e-5);
  EXPECT_NEAR(wrap_pi(s3.theta - s0.theta), 0, 1e-5);
}

// The moved camera, written by D and read back by -c, renders the window's image (the same seed
// and settings: within half an 8-bit level), and not the unmoved one.
TEST_F(Viewer, TheMovedCameraRendersTheSameImageFromItsSettingsFile) {
  const std::string flags = "-t 2 -s 32 -m 3 -r 120 90 --seed 3";
  RunResult w = run_window(flags + " --output-dir " + m_dir, "key `\nwait_spp 1\ndrag left 60 45 75 35 3\ndrag right 60 45 66 48 2\nwheel 1\nwait_spp 32\n"
                           "screenshot " + m_dir + "/window.png\nkey D\nsync\nquit\n");
  RunResult c = run(flags + " --quiet -c " + m_dir + "/cornell_cam_settings.txt -f " + m_dir + "/cli.png " + m_scene);
  ASSERT_EQ(c.status, 0) << c.output;
  RunResult u = run(flags + " --quiet -f " + m_dir + "/unmoved.png " + m_scene);
  ASSERT_EQ(u.status, 0) << u.output;
  EXPECT_LT(mean_abs_diff_levels(m_dir + "/window.png", m_dir + "/cli.png"), 0.5) << w.output;
  EXPECT_GT(mean_abs_diff_levels(m_dir + "/window.png", m_dir + "/unmoved.png"), 5.0) << "the drag moved nothing";
}
