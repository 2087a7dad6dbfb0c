// The pathtracer command: course flags parse unchanged, bad flags are named, and the real
// binary writes its images (PNG + _rate.png, EXR with metadata) or fails with a located error.
#include "cli.h"
#include "options.h"

#include <gtest/gtest.h>

#include <pty.h>
#include <regex>
#include <sys/wait.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "test_util.h"

using namespace pt;

namespace {

std::vector<std::string> split(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  std::string w;
  while (in >> w) out.push_back(w);
  return out;
}

using test::RunResult;

RunResult run(const std::string& args, const std::string& binary = PT_PATHTRACER) {
  return test::run_command(binary + " " + args);
}

const char* kTinyScene = R"(<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><up_axis>Y_UP</up_axis></asset>
  <library_lights><light id="L"><technique_common><point><color>4 4 4</color>
    <constant_attenuation>1</constant_attenuation><linear_attenuation>0</linear_attenuation>
    <quadratic_attenuation>0</quadratic_attenuation></point></technique_common></light></library_lights>
  <library_geometries>
    <geometry id="S"><extra><technique profile="CGL"><sphere><radius>1</radius></sphere></technique></extra></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="VS">
    <node id="l"><translate>0 3 3</translate><instance_light url="#L"/></node>
    <node id="s"><instance_geometry url="#S"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#VS"/></scene>
</COLLADA>
)";

// Each test writes its own copy: ctest runs the tests of this file in parallel processes, and one
// rewriting a file another is loading would make either fail.
std::string write_tiny_scene() {
  std::string path = test::temp_dir() + "/tiny_" + testing::UnitTest::GetInstance()->current_test_info()->name() + ".dae";
  std::ofstream(path) << kTinyScene;
  return path;
}

}  // namespace

TEST(Cli, CourseCommandsParseUnchanged) {
  CliOptions o = parse_cli(split("-t 8 -s 64 -l 4 -m 5 -r 480 360 -f p1_5.png CBspheres.dae"));
  EXPECT_EQ(o.params.threads, 8);
  EXPECT_EQ(o.params.spp, 64);
  EXPECT_EQ(o.params.light_samples, 4);
  EXPECT_EQ(o.params.max_depth, 5);
  EXPECT_EQ(o.params.width, 480);
  EXPECT_EQ(o.params.height, 360);
  EXPECT_EQ(o.output, "p1_5.png");
  EXPECT_EQ(o.scene_path, "CBspheres.dae");
  EXPECT_TRUE(o.params.adaptive);  // on by default, as in the course

  o = parse_cli(split("-t 8 -s 128 -a 64 0.05 -r 480 360 -m 12 -l 4 -b 0.23 -d 4.5 -f focus.png CBdragon.dae"));
  EXPECT_EQ(o.params.adaptive_batch, 64);
  EXPECT_FLOAT_EQ(o.params.adaptive_tolerance, 0.05f);
  EXPECT_EQ(o.params.max_depth, 12);
  EXPECT_FLOAT_EQ(o.params.lens_radius, 0.23f);
  EXPECT_FLOAT_EQ(o.params.focal_distance, 4.5f);

  o = parse_cli(split("-H -p 10 20 30 40 -c cam.txt -e env.exr s.dae"));
  EXPECT_TRUE(o.params.hemisphere);
  EXPECT_EQ(o.params.cell_x, 10);
  EXPECT_EQ(o.params.cell_h, 40);
  EXPECT_EQ(o.params.camera_file, "cam.txt");
  EXPECT_EQ(o.params.env_map, "env.exr");
  EXPECT_TRUE(o.output.empty());
  EXPECT_TRUE(o.output_dir.empty());  // the window saves into the current directory

  o = parse_cli(split("--output-dir shots s.dae"));
  EXPECT_EQ(o.output_dir, "shots");
}

TEST(Cli, DefaultsMatchTheCourse) {
  CliOptions o = parse_cli(split("scene.dae"));
  EXPECT_EQ(o.params.spp, 1);
  EXPECT_EQ(o.params.light_samples, 1);
  EXPECT_EQ(o.params.max_depth, 1);
  // But every core, not the course's one thread (docs/cs184-compat.md): the image is the same.
  EXPECT_EQ(o.params.threads, std::max(1, int(std::thread::hardware_concurrency())));
  EXPECT_EQ(parse_cli(split("-t 1 scene.dae")).params.threads, 1);
  EXPECT_FLOAT_EQ(o.params.lens_radius, 0);
  EXPECT_FLOAT_EQ(o.params.focal_distance, 4.7f);
  EXPECT_EQ(o.params.width, 800);
  EXPECT_EQ(o.params.height, 600);
  EXPECT_EQ(o.params.adaptive_batch, 32);
  EXPECT_FLOAT_EQ(o.params.adaptive_tolerance, 0.05f);
}

TEST(Cli, BadFlagsAreNamed) {
  struct Case {
    const char* args;
    const char* names;
  } cases[] = {
      {"-s abc s.dae", "-s"},         {"-s 0 s.dae", "-s"},          {"-m -1 s.dae", "-m"},
      {"-r 480 s.dae", "-r"},         {"-b nan s.dae", "-b"},        {"-d inf s.dae", "-d"},
      {"-b -1 s.dae", "-b"},          {"-x s.dae", "-x"},            {"-p 0 0 900 10 s.dae", "cell"},
      {"-f", "-f"},                   {"", "scene"},                 {"a.dae b.dae", "more than one"},
      {"-a 0 0.05 s.dae", "-a"},      {"-t 0 s.dae", "-t"},          {"-l 99999999999 s.dae", "-l"},
      {"-b 2e6 s.dae", "-b: 2e6 is out of range [0, 1e+06]"},  // a number out of range shows the range
      {"--output-dir s.dae", "scene"},  {"--output-dir d -f x.png s.dae", "--output-dir"},
  };
  for (const Case& c : cases) {
    try {
      parse_cli(split(c.args));
      ADD_FAILURE() << "accepted: " << c.args;
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find(c.names), std::string::npos) << c.args << " -> " << e.what();
    }
  }
}

TEST(Cli, RateImageName) {
  EXPECT_EQ(rate_image_path("out/p1_5.png"), "out/p1_5_rate.png");
  EXPECT_EQ(rate_image_path("x.exr"), "x_rate.png");
}

// --help against the option table (renderer/options.cpp): every option's flag is documented, with
// the table's course default where it has one, and every documented flag parses.
TEST(Cli, HelpDocumentsEveryFlag) {
  RunResult r = run("--help");
  EXPECT_EQ(r.status, 0);
  const std::string& help = r.output;
  auto entry = [&](const std::string& flag) {  // the flag's line and its continuation lines
    size_t at = help.find("\n  " + flag + " ");
    if (at == std::string::npos) at = help.find("\n  " + flag + ",");
    if (at == std::string::npos) return std::string();
    size_t end = help.find("\n  -", at + 1);
    return help.substr(at, end == std::string::npos ? std::string::npos : end - at);
  };
  for (const RenderOption& o : render_options()) {
    if (!*o.flag) continue;
    SCOPED_TRACE(o.name);
    const std::string text = entry(o.flag);
    ASSERT_FALSE(text.empty()) << o.flag << " is not in --help:\n" << help;
    if (o.type != OptionType::boolean && o.course != 0)
      EXPECT_NE(text.find(option_text(o, o.course)), std::string::npos) << "the default " << option_text(o, o.course)
                                                                          << " is not in: " << text;
  }
  for (const char* f : {"-s ", "-l ", "-t ", "-m ", "-e ", "-b ", "-d ", "-f ", "-r ", "-c ", "-a ", "-p ", "-H ",
                        "-h", "--file-camera", "--seed", "--no-adaptive", "--no-caustic-tracing", "--sampler", "--describe"})
    EXPECT_NE(help.find(f), std::string::npos) << f;
  // Every flag --help lists is one the parser takes (as a usage error at worst, never "unknown").
  std::smatch m;
  std::string rest = help;
  int flags = 0;
  while (std::regex_search(rest, m, std::regex("\n  (--?[a-zA-Z][a-z-]*)"))) {
    const std::string flag = m[1];
    rest = m.suffix();
    ++flags;
    RunResult f = run(flag + " " + test::own_scene("cornell.dae") + " --describe");
    EXPECT_EQ(f.output.find("unknown option"), std::string::npos) << flag << ": " << f.output;
  }
  EXPECT_GT(flags, 25);
}

TEST(Cli, RendersPngRateImageAndExrWithMetadata) {
  std::string scene = write_tiny_scene();
  std::string dir = test::temp_dir();
  RunResult r = run("-t 3 -s 4 -m 2 -r 64 48 --quiet -f " + dir + "/tiny.png " + scene);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("samples/s"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("rays/s"), std::string::npos) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("error estimate [0-9.]+(e-?[0-9]+)?\\n"))) << r.output;
  // One sample a pixel leaves no halves to compare: the summary says so instead of "inf".
  r = run("-s 1 -m 2 -r 32 24 --quiet -f " + dir + "/one.png " + scene);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("error estimate n/a (needs 2 or more spp)"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("inf"), std::string::npos) << r.output;
  for (const char* name : {"/tiny.png", "/tiny_rate.png"}) {
    auto in = OIIO::ImageInput::open(dir + name);
    ASSERT_TRUE(in) << name;
    EXPECT_EQ(in->spec().width, 64);
    EXPECT_EQ(in->spec().height, 48);
  }
  r = run("-s 4 -m 2 -r 64 48 --seed 5 --quiet -f " + dir + "/tiny.exr " + scene);
  ASSERT_EQ(r.status, 0) << r.output;
  auto in = OIIO::ImageInput::open(dir + "/tiny.exr");
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
  EXPECT_EQ(in->spec().get_string_attribute("pathtracer:seed"), "5");
  EXPECT_EQ(in->spec().get_string_attribute("pathtracer:max_depth"), "2");
  EXPECT_EQ(in->spec().get_string_attribute("pathtracer:nonfinite_samples"), "0");
  EXPECT_FALSE(in->spec().get_string_attribute("pathtracer:wall_seconds").empty());
  EXPECT_FALSE(in->spec().get_string_attribute("pathtracer:achieved_spp").empty());
}

TEST(Cli, BadSceneFailsWithALocatedMessage) {
  std::string path = test::temp_dir() + "/broken.dae";
  std::ofstream(path) << "<COLLADA><asset><up_axis>W_UP</up_axis></asset></COLLADA>";
  RunResult r = run("--quiet -f " + test::temp_dir() + "/never.png " + path);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("broken.dae:1"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("up_axis"), std::string::npos) << r.output;
  EXPECT_FALSE(test::file_exists(test::temp_dir() + "/never.png"));

  r = run("--quiet -f " + test::temp_dir() + "/never.png /nonexistent/scene.dae");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("/nonexistent/scene.dae"), std::string::npos) << r.output;
}

// An image that could not be saved fails the command at once, before the scene loads ("Loaded ..."
// is never printed), not after the render.
TEST(Cli, AnUnwritableOutputFailsBeforeTheRender) {
  std::string scene = write_tiny_scene(), dir = test::temp_dir();
  RunResult r = run("-s 4 -r 64 48 -f " + dir + "/out.notaformat " + scene);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("out.notaformat: cannot write this image format"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("Loaded"), std::string::npos) << r.output;

  r = run("-s 4 -r 64 48 -f " + dir + "/no_such_folder/out.png " + scene);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("cannot write into the folder " + dir + "/no_such_folder"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("Loaded"), std::string::npos) << r.output;
  EXPECT_FALSE(test::file_exists(dir + "/no_such_folder"));
}

// The image module (renderer/util/image_module.h) is looked for beside the executable first, then where
// the build put it: a copied pair works, and a broken copy falls back to the built one.
TEST(Cli, ImageModuleBesideTheBinaryFirstThenTheBuiltOne) {
  std::string build_dir = PT_PATHTRACER;
  build_dir.resize(build_dir.find_last_of('/') + 1);
  std::string dir = test::temp_dir() + "/relocated/";
  std::filesystem::create_directories(dir);
  auto copy = [](const std::string& from, const std::string& to) {
    std::filesystem::copy_file(from, to, std::filesystem::copy_options::overwrite_existing);
  };
  copy(PT_PATHTRACER, dir + "pathtracer");
  copy(build_dir + "pt_imageio.so", dir + "pt_imageio.so");
  std::string scene = write_tiny_scene(), out = dir + "moved.png";
  // LD_DEBUG=files names each library as it is loaded.
  RunResult r = run("-s 1 -r 16 12 --quiet -f " + out + " " + scene, "LD_DEBUG=files " + dir + "pathtracer");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("file=" + dir + "pt_imageio.so"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("file=" + build_dir + "pt_imageio.so"), std::string::npos) << r.output;
  EXPECT_TRUE(test::file_exists(out));

  std::ofstream(dir + "pt_imageio.so", std::ios::trunc) << "not a shared object";
  std::remove(out.c_str());
  r = run("-s 1 -r 16 12 --quiet -f " + out + " " + scene, "LD_DEBUG=files " + dir + "pathtracer");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("file=" + build_dir + "pt_imageio.so"), std::string::npos) << r.output;
  EXPECT_TRUE(test::file_exists(out));
}

TEST(Cli, MoreThreadsThanCoresStillWork) {
  std::string scene = write_tiny_scene();
  RunResult r = run("-t 64 -s 2 -r 40 30 --quiet -f " + test::temp_dir() + "/many.png " + scene);
  EXPECT_EQ(r.status, 0) << r.output;
}

TEST(Cli, DescribePrintsTheFeatureSetAndMemory) {
  RunResult r = run("--describe " + test::own_scene("cornell.dae"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("materials:        diffuse, emission, glass, mirror"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("lights:           area"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("specialised: delta no-microfacet no-infinite-lights"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("bytes per primitive"), std::string::npos) << r.output;
  // The defaults (-s 1 -m 1): one sample is the pixel centre, and one bounce has no caustic; the
  // line says what would light-trace them.
  EXPECT_NE(r.output.find("caustics:         path traced only (-s 2 -m 2 or more would light-trace them)\n"),
            std::string::npos)
      << r.output;
  r = run("-s 16 -m 5 --describe " + test::own_scene("cornell.dae"));
  EXPECT_NE(r.output.find("caustics:         light traced"), std::string::npos) << r.output;
  r = run("--describe " + test::own_scene("cornell.dae"));
  EXPECT_NE(r.output.find("path loop:        specialised: delta no-microfacet no-infinite-lights"), std::string::npos)
      << r.output;
  // Embree's native packet width: 16 with AVX-512, 8 below it.
  EXPECT_TRUE(std::regex_search(r.output, std::regex("ray queries:      paths in Embree packets of (8|16)\n")))
      << r.output;
  r = run("--describe --no-ray-packets " + test::own_scene("cornell.dae"));  // an experiment's switch, gone
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("--no-ray-packets"), std::string::npos) << r.output;
  r = run("--describe -H " + test::own_scene("cornell.dae"));  // its direct-light rays go one at a time
  EXPECT_NE(r.output.find("ray queries:      one path at a time"), std::string::npos) << r.output;
  r = run("-s 16 -m 5 --describe --no-caustic-tracing " + test::own_scene("cornell.dae"));
  EXPECT_NE(r.output.find("caustics:         path traced only\n"), std::string::npos) << r.output;
  r = run("-s 16 -m 5 --describe " + test::own_scene("dof.dae"));  // no mirror or glass: nothing to trace
  EXPECT_NE(r.output.find("caustics:         path traced only\n"), std::string::npos) << r.output;
  r = run("--describe " + test::own_scene("dof.dae"));  // nor at any setting
  EXPECT_NE(r.output.find("caustics:         path traced only\n"), std::string::npos) << r.output;
}

TEST(Cli, CausticLightPathsAreRecordedInTheExrHeader) {
  std::string dir = test::temp_dir(), scene = test::own_scene("cornell.dae");
  for (bool traced : {true, false}) {
    std::string out = dir + (traced ? "/lt.exr" : "/pt.exr");
    RunResult r = run(std::string("-s 4 -m 3 -r 64 48 --keep-fov --quiet ") + (traced ? "" : "--no-caustic-tracing ") +
                      "-f " + out + " " + scene);
    ASSERT_EQ(r.status, 0) << r.output;
    auto in = OIIO::ImageInput::open(out);
    ASSERT_TRUE(in);
    std::string paths = in->spec().get_string_attribute("pathtracer:caustic_light_paths");
    if (traced) EXPECT_GT(std::stoll(paths), 0) << paths;
    else EXPECT_EQ(paths, "0");
  }
}

TEST(Cli, ErrorLogTargetErrorAndReference) {
  std::string dir = test::temp_dir(), scene = test::own_scene("dof.dae");
  // A converged reference, then a run that logs its true error against it.
  RunResult r = run("-t 2 -s 256 -m 2 -r 40 30 --keep-fov --no-adaptive --seed 7 --quiet -f " + dir + "/ref.exr " + scene);
  ASSERT_EQ(r.status, 0) << r.output;
  r = run("-t 2 -s 32 -m 2 -r 40 30 --keep-fov --no-adaptive --quiet --error-log " + dir + "/log.csv --reference " + dir +
          "/ref.exr -f " + dir + "/run.png " + scene);
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(dir + "/log.csv");
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header, "seconds,spp,error_estimate,rmse,rel_mse");
  std::vector<double> rel;
  while (std::getline(in, line)) rel.push_back(std::stod(line.substr(line.find_last_of(',') + 1)));
  ASSERT_EQ(rel.size(), 6u);  // passes of 1, 2, 4, 8, 16, 32 spp
  EXPECT_LT(rel.back(), rel.front() / 8);  // the true error falls as samples accumulate

  // The error target stops the render before its sample budget.
  r = run("-t 2 -s 4096 -m 2 -r 40 30 --no-adaptive --quiet --target-error 0.02 -f " + dir + "/target.png " + scene);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("error target reached"), std::string::npos) << r.output;

  // A reference of the wrong size is refused by name.
  r = run("-s 2 -r 20 10 --quiet --reference " + dir + "/ref.exr -f " + dir + "/bad.png " + scene);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("ref.exr"), std::string::npos) << r.output;
}

// --progress-log: the bar's fraction and ETA (ProgressEstimate) row by row, known from the first
// pass on, ending at 1 and 0 s with the last pass; beside them the sample budget's fraction and
// the samples taken and predicted left, none left at the end.
TEST(Cli, ProgressLogFollowsTheRenderToItsEnd) {
  std::string dir = test::temp_dir();
  RunResult r = run("-t 2 -s 256 -m 2 -r 40 30 --keep-fov --quiet --progress-log " + dir + "/progress.csv -f " + dir +
                    "/run.png " + test::own_scene("dof.dae"));
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(dir + "/progress.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "seconds,progress,eta,budget_progress,pass_end,samples,samples_left");
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    ASSERT_EQ(row.size(), 7u) << line;
    for (double v : row) ASSERT_TRUE(std::isfinite(v)) << line;
    rows.push_back(row);
  }
  ASSERT_GE(rows.size(), 2u);
  int passes = 0;
  for (size_t k = 0; k < rows.size(); ++k) {
    const std::vector<double>& row = rows[k];
    if (k > 0) EXPECT_GE(row[0], rows[k - 1][0]) << k;
    EXPECT_GE(row[1], 0) << k;
    EXPECT_LE(row[1], 1) << k;
    EXPECT_GE(row[3], 0) << k;
    EXPECT_LE(row[3], 1) << k;
    if (passes > 0) EXPECT_GE(row[2], 0) << k << ": the first pass gave a rate";
    passes += row[4] == 1;
  }
  EXPECT_GE(passes, 2);
  EXPECT_LE(passes, 9);  // 1, 2, 4, ... 256 spp at most
  EXPECT_EQ(rows.back()[4], 1);
  EXPECT_EQ(rows.back()[1], 1);
  EXPECT_EQ(rows.back()[2], 0);
  EXPECT_EQ(rows.back()[3], 1);
  EXPECT_GT(rows.back()[5], 0);
  EXPECT_LE(rows.back()[5], 256 * 40 * 30);
  EXPECT_EQ(rows.back()[6], 0);
}

// Runs argv[0] with argv on a pseudo-terminal (where the progress bar draws) and returns what it
// wrote there, stdout and stderr together.
std::string run_on_terminal(const std::vector<std::string>& argv, int& status) {
  int terminal = -1;
  const pid_t pid = forkpty(&terminal, nullptr, nullptr, nullptr);
  if (pid < 0) {
    status = -1;
    return "forkpty failed";
  }
  if (pid == 0) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  std::string out;
  char buf[4096];
  for (;;) {  // read() fails with EIO once the child has closed the terminal
    const ssize_t n = read(terminal, buf, sizeof buf);
    if (n > 0) out.append(buf, size_t(n));
    else if (n < 0 && errno == EINTR) continue;
    else break;
  }
  int st = 0;
  waitpid(pid, &st, 0);
  close(terminal);
  status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return out;
}

// On a terminal the progress bar shows the latest error estimate, and with --target-error its ETA
// follows that estimate's 1/time decay (ProgressEstimate, whose arithmetic test_progress.cpp checks),
// not the sample budget; so does its fill, elapsed / (elapsed + ETA). A budget of 2^20 spp, which
// the target ends at a few thousand, would keep the fill at the sample fraction, under 1%: the fill
// must pass ten times the share of the budget the run used. Nothing here depends on how fast the
// machine is: the fill and the sample counts are ratios of the same run's own numbers.
TEST(Cli, ProgressBarShowsTheErrorAndItsEtaTowardsTheTarget) {
  const std::string out = test::temp_dir() + "/bar.exr";
  const int budget = 1048576;
  int status = 0;
  const std::string text = run_on_terminal({PT_PATHTRACER, "-t", "2", "-s", std::to_string(budget), "-r", "128", "96",
                                            "--keep-fov", "--no-adaptive", "--target-error", "0.00002", "-f", out,
                                            test::own_scene("cornell.dae")},
                                           status);
  ASSERT_EQ(status, 0) << text;
  EXPECT_NE(text.find("error target reached"), std::string::npos) << text;
  auto in = OIIO::ImageInput::open(out);
  ASSERT_TRUE(in);
  const double used = std::stod(in->spec().get_string_attribute("pathtracer:achieved_spp")) / budget;
  ASSERT_GT(used, 0);
  const std::regex drawn(R"(([0-9.]+)%  ([0-9.]+)s elapsed, ETA ([0-9.]+)s error ([0-9.e+-]+))");
  int lines = 0;
  double most_filled = 0;
  for (std::sregex_iterator m(text.begin(), text.end(), drawn), end; m != end; ++m, ++lines) {
    const double fill = std::stod((*m)[1]) / 100, elapsed = std::stod((*m)[2]), eta = std::stod((*m)[3]);
    EXPECT_GT(std::stod((*m)[4]), 0.0) << m->str();
    most_filled = std::max(most_filled, fill);
    // The fill is the share of the expected time gone, within the rounding of the printed numbers
    // (0.05 s each, 0.05% the fill) and the cap of 99.9% until done.
    if (elapsed + eta < 1) continue;
    const double lo = std::max(0.0, elapsed - 0.05) / (elapsed + eta + 0.1), hi = (elapsed + 0.05) / (elapsed + eta - 0.1);
    EXPECT_GE(fill, std::min(0.999, lo) - 0.0005) << m->str();
    EXPECT_LE(fill, std::min(0.999, hi) + 0.0005) << m->str();
  }
  EXPECT_GE(lines, 1) << text;
  EXPECT_GT(most_filled, 10 * used) << "the bar followed the sample budget (" << used << " of it used), not the target";
}

#if defined(__SANITIZE_ADDRESS__)
#define PT_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PT_TEST_ASAN 1
#endif
#endif

// A render too large for the memory the process may use ends with a message that names the size,
// not "std::bad_alloc", and writes no image.
TEST(Cli, OutOfMemoryNamesTheRenderSize) {
#ifdef PT_TEST_ASAN
  GTEST_SKIP() << "ulimit -v and AddressSanitizer's shadow memory do not mix";
#endif
  const std::string out = test::temp_dir() + "/oom.png";
  std::remove(out.c_str());
  // 3 GB of address space; the film's statistics alone need about 12 GB.
  RunResult r = run("-t 1 -s 1 -r 16384 16384 --quiet -f " + out + " " + write_tiny_scene(),
                    std::string("ulimit -v 3000000; ") + PT_PATHTRACER);
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("pathtracer: out of memory for a 16384x16384 render"), std::string::npos) << r.output;
  EXPECT_FALSE(test::file_exists(out));
}
