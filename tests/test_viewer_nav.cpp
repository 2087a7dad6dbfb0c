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

// C: the course's cell mode. A left drag's rubber band becomes the -p cell the render redoes,
// painted over the image the window shows: a setting changed in cell mode changes only the cell,
// which is the CLI's -p render of it; C again renders the whole frame.
TEST_F(Viewer, CellModeRendersTheRubberBandsRectangleOnly) {
  const std::string flags = "-t 2 -s 16 -m 3 -r 120 90 --seed 3";
  RunResult r = run_window(flags, "key `\nwait_spp 16\nscreenshot " + m_dir + "/full.png\nkey C\ndrag left 30 20 70 50 4\n"
                           "key ,\nkey ,\nkey ,\nwait_spp 16\nscreenshot " + m_dir + "/cell.png\nkey C\nwait_spp 16\n"
                           "screenshot " + m_dir + "/after.png\nquit\n");
  ASSERT_EQ(r.status, 0) << r.output;
  // (30, 20)..(70, 50) in a 120x90 window: columns 30..69, rows 20..49 from the top; -p counts
  // from the bottom-left, so the cell starts at row 90 - 50 = 40.
  for (const char* said : {"cell mode: on", "cell: 30 40 40 30", "cell mode: off", "cell: whole frame"})
    EXPECT_NE(r.output.find(said), std::string::npos) << said << "\n" << r.output;
  RunResult c = run(flags + " -m 0 -p 30 40 40 30 --quiet -f " + m_dir + "/cli_cell.png " + m_scene);
  ASSERT_EQ(c.status, 0) << c.output;
  const ImageRGB full = read_image(m_dir + "/full.png"), cell = read_image(m_dir + "/cell.png");
  const ImageRGB after = read_image(m_dir + "/after.png"), cli = read_image(m_dir + "/cli_cell.png");
  ASSERT_EQ(cell.width, 120);
  ASSERT_EQ(cli.width, 40);
  auto levels = [](Vec3 a, Vec3 b) { return (std::abs(a.x - b.x) + std::abs(a.y - b.y) + std::abs(a.z - b.z)) * 255 / 3; };
  double outside_kept = 0, inside_cli = 0, outside_after = 0;
  int n_out = 0;
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 120; ++x) {
      const size_t i = size_t(y) * 120 + x;
      if (x >= 30 && x < 70 && y >= 20 && y < 50) {
        inside_cli += levels(cell.pixels[i], cli.pixels[size_t(y - 20) * 40 + (x - 30)]);
      } else {  // the panel is hidden (`), the band drawn only while dragging
        outside_kept += levels(cell.pixels[i], full.pixels[i]);
        outside_after += levels(after.pixels[i], full.pixels[i]);
        ++n_out;
      }
    }
  EXPECT_LT(inside_cli / (40 * 30), 0.5) << "the cell is not the CLI's -p render at depth 0";
  EXPECT_LT(outside_kept / n_out, 0.5) << "outside the cell the image changed";
  EXPECT_GT(outside_after / n_out, 5.0) << "leaving cell mode did not render the whole frame at depth 0";
}
