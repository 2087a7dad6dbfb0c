// What a new user meets first: every core by default, hints for settings that will disappoint
// (shallow depth with mirror and glass, one sample, a crop that hides the scene), an error target
// without a budget that renders until the target, one-line usage errors with the nearest option,
// --version, and a clear message for a file that is not a scene.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <thread>

#include "camera.h"
#include "cli.h"
#include "hints.h"
#include "render_scene.h"
#include "scene_file.h"
#include "test_util.h"
#include "version.h"

using namespace pt;

namespace {

std::vector<std::string> words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

bool any_has(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& l : lines)
    if (l.find(text) != std::string::npos) return true;
  return false;
}

// The hints for `flags` on one of our scenes, as the pathtracer command computes them.
std::vector<std::string> hints_for(const std::string& flags, const std::string& scene) {
  CliOptions o = parse_cli(words(flags + " " + scene));
  SceneDesc desc = load_scene(scene);
  auto rs = make_render_scene(desc, o.params);
  return render_hints(o, rs->features, rs->camera, desc.geometry_bounds(), true);
}

}  // namespace

TEST(FirstRun, ShallowDepthWithMirrorOrGlassGetsAHintNamingTheDepth) {
  // cornell.dae has a mirror and a glass sphere (scenes/README.md).
  const std::string cornell = test::own_scene("cornell.dae");
  const auto shallow = hints_for("-s 16 -m 1", cornell);
  EXPECT_TRUE(any_has(shallow, "-m 1 leaves mirror and glass black")) << ::testing::PrintToString(shallow);
  EXPECT_TRUE(any_has(hints_for("-s 16 -m 2", cornell), "-m 2 leaves mirror and glass dark"));
  EXPECT_FALSE(any_has(hints_for("-s 16 -m 3", cornell), "mirror and glass"));
  // A scene of diffuse surfaces only is not told about mirrors.
  const std::string diffuse = test::temp_dir() + "/diffuse_only.dae";
  std::ofstream(diffuse) << test::diffuse_sphere_scene(0.5f, 4, 40, "<point><color>1 1 1</color></point>");
  EXPECT_FALSE(any_has(hints_for("-s 16 -m 1", diffuse), "mirror"));
}

TEST(FirstRun, OneSampleGetsAHintUnlessAnErrorTargetDecides) {
  const std::string cornell = test::own_scene("cornell.dae");
  EXPECT_TRUE(any_has(hints_for("-m 5", cornell), "-s 1 takes one sample"));
  EXPECT_FALSE(any_has(hints_for("-m 5 -s 64", cornell), "-s 1"));
  EXPECT_FALSE(any_has(hints_for("-m 5 --target-error 0.01", cornell), "-s 1"));
}

TEST(FirstRun, ACropThatHidesMostOfTheSceneNamesKeepFovAndFrameScene) {
  const std::string dof = test::own_scene("dof.dae");
  // The whole view shows all of it; a small -r is a centre crop that shows a small part.
  EXPECT_FALSE(any_has(hints_for("-s 16 -m 5", dof), "--keep-fov"));
  const auto cropped = hints_for("-s 16 -m 5 -r 160 120", dof);
  EXPECT_TRUE(any_has(cropped, "--keep-fov")) << ::testing::PrintToString(cropped);
  EXPECT_TRUE(any_has(cropped, "--frame-scene"));
  EXPECT_FALSE(any_has(hints_for("-s 16 -m 5 -r 160 120 --keep-fov", dof), "--keep-fov"));
  EXPECT_FALSE(any_has(hints_for("-s 16 -m 5 -r 160 120 --frame-scene", dof), "--keep-fov"));
}

TEST(FirstRun, EveryCoreUnlessTIsGiven) {
  EXPECT_EQ(parse_cli(words("s.dae")).params.threads, std::max(1, int(std::thread::hardware_concurrency())));
  EXPECT_EQ(parse_cli(words("-t 3 s.dae")).params.threads, 3);
}

TEST(FirstRun, AnErrorTargetWithoutABudgetRendersUntilTheTarget) {
  CliOptions o = parse_cli(words("--target-error 0.01 s.dae"));
  EXPECT_EQ(o.params.spp, int(render_option("spp").max));
  EXPECT_EQ(parse_cli(words("--target-error 0.01 -s 16 s.dae")).params.spp, 16);
  EXPECT_EQ(parse_cli(words("s.dae")).params.spp, 1);  // no target: the course's one sample
  // The real command stops at the target, well before any budget, and says so.
  const std::string out = test::temp_dir() + "/target.exr";
  test::RunResult r = test::run_command(std::string(PT_PATHTRACER) + " --quiet -t 2 -m 2 -r 64 48 --target-error 0.02 -f " +
                                        out + " " + test::own_scene("cornell.dae"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("error target reached"), std::string::npos) << r.output;
}

TEST(FirstRun, AMistypedOptionGetsOneLineWithTheNearestOption) {
  EXPECT_EQ(nearest_option("--target-eror"), "--target-error");
  EXPECT_EQ(nearest_option("--keepfov"), "--keep-fov");
  EXPECT_EQ(nearest_option("--frame-scen"), "--frame-scene");
  EXPECT_EQ(nearest_option("--completely-unknown"), "");
  // A long spelling of a one-letter flag points at the flag, beside the long option it is near.
  EXPECT_EQ(nearest_option("--sampels"), "-s or --sampler");
  EXPECT_EQ(nearest_option("--max-depht"), "-m");
  EXPECT_EQ(nearest_option("--light-samples"), "-l");
  try {
    parse_cli(words("--target-eror 0.1 s.dae"));
    ADD_FAILURE() << "accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean --target-error?"), std::string::npos) << e.what();
  }
  test::RunResult r = test::run_command(std::string(PT_PATHTRACER) + " --target-eror 0.1 s.dae");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.output, "pathtracer: unknown option '--target-eror' (did you mean --target-error?) (see --help)\n");
  r = test::run_command(std::string(PT_PATHTRACER) + " -s abc s.dae");
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST(FirstRun, VersionNamesTheCommitEmbreeAndOpenImageIO) {
  test::RunResult r = test::run_command(std::string(PT_PATHTRACER) + " --version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.output.rfind("pathtracer ", 0), 0u) << r.output;
  EXPECT_NE(r.output.find("(commit "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Embree 3."), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("OpenImageIO 2."), std::string::npos) << r.output;
  EXPECT_EQ(r.output, version_text("pathtracer") + "\n");
}

TEST(FirstRun, AFileThatIsNotASceneIsNamedAsSuch) {
  const std::string dir = test::temp_dir();
  auto error_of = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir + "/" + name, std::ios::binary) << bytes;
    try {
      load_scene(dir + "/" + name);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("loaded");
  };
  EXPECT_NE(error_of("pic.png", std::string("\x89PNG\r\n\x1a\n", 8) + "rest").find("not a COLLADA or glTF scene (a PNG image)"),
            std::string::npos);
  EXPECT_NE(error_of("notes.dae", "just some text\n").find("notes.dae: not a COLLADA or glTF scene"), std::string::npos);
  EXPECT_NE(error_of("page.dae", "<html><body>hi</body></html>").find("not a COLLADA scene: the root element is <html>"),
            std::string::npos);
  EXPECT_NE(error_of("empty.dae", "").find("not a COLLADA or glTF scene (an empty file)"), std::string::npos);
}

// A folder or a mistyped file name given as the scene: the message says what it is and, for a
// missing file, the nearest scene file's name in its folder (CBsphere.dae: CBspheres.dae).
TEST(FirstRun, AFolderOrAMistypedSceneNameSaysWhatToGive) {
  const std::string dir = test::temp_dir() + "/first_run_scenes";
  test::run_command("rm -rf " + dir + " && mkdir -p " + dir);
  for (const char* f : {"CBspheres.dae", "CBbunny.dae", "notes.txt"}) std::ofstream(dir + "/" + f) << "x";
  auto message = [](const std::string& path) {
    try {
      read_scene_bytes(path);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("(read)");
  };
  EXPECT_EQ(message(dir), dir + ": is a folder, not a scene file (it holds CBbunny.dae, CBspheres.dae)");
  EXPECT_EQ(message(dir + "/CBsphere.dae"),
            dir + "/CBsphere.dae: cannot open file (no such file; did you mean " + dir + "/CBspheres.dae?)");
  EXPECT_EQ(message(dir + "/dragon.dae"), dir + "/dragon.dae: cannot open file (no such file)");
  // The command says the same on one line, and the Loaded line counts the default light as such.
  test::RunResult r = test::run_command(std::string(PT_PATHTRACER) + " -f x.png " + dir + "/CBsphere.dae");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("did you mean " + dir + "/CBspheres.dae?"), std::string::npos) << r.output;
  // One triangle, no lights, no emitters: lit by the default environment and sun.
  const std::string unlit = dir + "/triangle.gltf", out = test::temp_dir() + "/first_run_triangle.png";
  std::ofstream(unlit) << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
  r = test::run_command(std::string(PT_PATHTRACER) + " -t 2 -s 1 -r 32 24 -f " + out + " " + unlit);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("0 spheres, no lights of its own (the default white environment and sun)"), std::string::npos)
      << r.output;
  r = test::run_command(std::string(PT_PATHTRACER) + " -t 2 -s 1 -r 32 24 -f " + out + " " + test::own_scene("cornell_gltf.glb"));
  EXPECT_NE(r.output.find("0 spheres, 1 light in"), std::string::npos) << r.output;
}
