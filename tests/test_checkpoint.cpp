// Checkpoints (renderer/checkpoint.h) through the CLI and the render lifecycle (render_job.h): a
// killed render resumes to the same bits, a larger budget continues a finished one, another
// render's or a damaged checkpoint is refused, or, where the caller goes on, leaves the render fresh.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <OpenImageIO/imageio.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>

#include "render_job.h"
#include "scene_file.h"
#include "session.h"
#include "test_util.h"

namespace pt {
namespace {

using test::RunResult;

RunResult run(const std::string& args) { return test::run_command(std::string(PT_PATHTRACER) + " " + args); }


// The pixels of an EXR, for bit-for-bit comparisons (the headers differ: times, checkpoint notes).
std::vector<float> exr_pixels(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return {};
  const OIIO::ImageSpec& s = in->spec();
  std::vector<float> px(size_t(s.width) * s.height * s.nchannels);
  in->read_image(0, 0, 0, s.nchannels, OIIO::TypeDesc::FLOAT, px.data());
  return px;
}

// kill -9 after the first checkpoint, then the same command: it resumes (not from zero) and its
// image is the uninterrupted render's, bit for bit.
TEST(Checkpoint, AKilledRenderResumesToTheSameBits) {
  const std::string dir = test::temp_dir() + "/checkpoint_kill", scene = test::own_scene("cornell.dae");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string flags = "-t 2 -s 1024 -m 5 -r 64 48 --no-adaptive --seed 9 ";
  RunResult whole = run(flags + "--quiet -f " + dir + "/whole.exr " + scene);
  ASSERT_EQ(whole.status, 0) << whole.output;
  const std::string resumable = flags + "--checkpoint " + dir + "/c.ckpt --checkpoint-interval 0 -f " + dir + "/resumed.exr " + scene;
  // In the background; killed once the first checkpoint is in place.
  const std::string killer = "sh -c '" + std::string(PT_PATHTRACER) + " " + resumable + " > /dev/null 2>&1 & pid=$!; " +
                             "while [ ! -f " + dir + "/c.ckpt ]; do sleep 0.01; done; kill -9 $pid; wait $pid 2>/dev/null; true' 2>/dev/null";
  ASSERT_EQ(std::system(killer.c_str()), 0);
  ASSERT_FALSE(test::file_exists(dir + "/resumed.exr")) << "killed before it finished";
  RunResult again = run(resumable);
  ASSERT_EQ(again.status, 0) << again.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(again.output, m, std::regex(R"(Resuming from \S+: ([0-9.]+) spp a pixel)"))) << again.output;
  EXPECT_GT(std::stod(m[1]), 0.0);
  EXPECT_LT(std::stod(m[1]), 1024.0) << "it resumed a render that had finished: nothing was tested";
  EXPECT_NE(again.output.find(" written in "), std::string::npos) << again.output;
  const std::vector<float> a = exr_pixels(dir + "/whole.exr"), b = exr_pixels(dir + "/resumed.exr");
  ASSERT_FALSE(a.empty());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0) << "the resumed image differs";
  // Run once more: the checkpoint says the render is done, so the image is written again unchanged.
  RunResult done = run(resumable);
  ASSERT_EQ(done.status, 0) << done.output;
  EXPECT_EQ(exr_pixels(dir + "/resumed.exr"), b);
}

// A finished render's checkpoint continues under a larger -s: the image is the larger budget's render
// from the start, bit for bit (the adaptive rule's stops included); a smaller -s is refused.
TEST(Checkpoint, ALargerBudgetContinuesAFinishedRender) {
  const std::string dir = test::temp_dir() + "/checkpoint_more", scene = test::own_scene("cornell.dae");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string flags = "-t 2 -m 4 -r 48 36 -a 4 0.15 --seed 3 --quiet ", ck = " --checkpoint " + dir + "/c.ckpt";
  RunResult whole = run(flags + "-s 64 -f " + dir + "/whole.exr " + scene);
  ASSERT_EQ(whole.status, 0) << whole.output;
  RunResult first = run(flags + "-s 16" + ck + " -f " + dir + "/more.exr " + scene);
  ASSERT_EQ(first.status, 0) << first.output;
  const std::vector<float> sixteen = exr_pixels(dir + "/more.exr");
  RunResult more = run(flags + "-s 64" + ck + " -f " + dir + "/more.exr " + scene);
  ASSERT_EQ(more.status, 0) << more.output;
  const std::vector<float> a = exr_pixels(dir + "/whole.exr"), b = exr_pixels(dir + "/more.exr");
  ASSERT_FALSE(a.empty());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_NE(sixteen, b) << "the larger budget added nothing";
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0) << "the continued image differs";
  RunResult fewer = run(flags + "-s 8" + ck + " -f " + dir + "/x.exr " + scene);
  EXPECT_EQ(fewer.status, 1);
  EXPECT_NE(fewer.output.find("a budget can grow, not shrink"), std::string::npos) << fewer.output;
}

// A checkpoint belongs to one render: another option that changes the image, another scene, a file
// that is not a checkpoint or is cut short are refused with a message naming the file.
TEST(Checkpoint, AnotherRendersOrADamagedCheckpointIsRefused) {
  const std::string dir = test::temp_dir() + "/checkpoint_refused", scene = test::own_scene("cornell.dae");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string ck = dir + "/c.ckpt", out = " -f " + dir + "/x.exr ";
  RunResult first = run("-t 2 -s 8 -m 3 -r 32 24 --quiet --checkpoint " + ck + out + scene);
  ASSERT_EQ(first.status, 0) << first.output;
  RunResult other = run("-t 2 -s 8 -m 4 -r 32 24 --quiet --checkpoint " + ck + out + scene);
  EXPECT_EQ(other.status, 1);
  EXPECT_NE(other.output.find(ck + ": a checkpoint of another render"), std::string::npos) << other.output;
  EXPECT_NE(other.output.find("max_depth 4"), std::string::npos) << "it shows what differs: " << other.output;
  // The thread count and the limits do not change the image: the checkpoint is this render's.
  RunResult threads = run("-t 1 -s 8 -m 3 -r 32 24 --quiet --time-limit 100 --checkpoint " + ck + out + scene);
  EXPECT_EQ(threads.status, 0) << threads.output;
  std::string bytes;
  {
    std::ifstream in(ck, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  std::ofstream(ck, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  RunResult cut = run("-t 2 -s 8 -m 3 -r 32 24 --quiet --checkpoint " + ck + out + scene);
  EXPECT_EQ(cut.status, 1);
  EXPECT_NE(cut.output.find(ck + ": damaged"), std::string::npos) << cut.output;
  std::ofstream(ck, std::ios::binary) << "not a checkpoint at all";
  RunResult junk = run("-t 2 -s 8 -m 3 -r 32 24 --quiet --checkpoint " + ck + out + scene);
  EXPECT_EQ(junk.status, 1);
  EXPECT_NE(junk.output.find(ck + ": not a pathtracer checkpoint"), std::string::npos) << junk.output;
  RunResult window = run("--checkpoint " + ck + " " + scene);
  EXPECT_EQ(window.status, 1);
  EXPECT_NE(window.output.find("--checkpoint needs -f"), std::string::npos) << window.output;
}

// A .gltf's buffers are part of the scene: a checkpoint of the scene before its .bin changed is
// another render's, though the .gltf itself is the same.
TEST(Checkpoint, AGltfWhoseBufferChangedIsAnotherRender) {
  const std::string dir = test::temp_dir() + "/checkpoint_gltf";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  // A unit quad: four positions, then six 16-bit indices.
  auto write_bin = [&](float x0) {
    const float positions[12] = {x0, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    std::ofstream bin(dir + "/quad.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(positions), sizeof positions);
    bin.write(reinterpret_cast<const char*>(indices), sizeof indices);
  };
  write_bin(-1);
  std::ofstream(dir + "/quad.gltf")
      << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "buffers": [{"uri": "quad.bin", "byteLength": 60}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
                    {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
  const std::string cmd = "-t 2 -s 8 -m 3 -r 32 24 --quiet --checkpoint " + dir + "/c.ckpt -f " + dir + "/x.exr " + dir +
                          "/quad.gltf";
  RunResult first = run(cmd);
  ASSERT_EQ(first.status, 0) << first.output;
  RunResult same = run(cmd);
  EXPECT_EQ(same.status, 0) << "the same files continue the checkpoint: " << same.output;
  write_bin(-0.5f);  // inside the accessor's bounds: the scene still loads
  RunResult changed = run(cmd);
  EXPECT_EQ(changed.status, 1) << changed.output;
  EXPECT_NE(changed.output.find("a checkpoint of another render"), std::string::npos) << changed.output;
  EXPECT_NE(changed.output.find("quad.bin"), std::string::npos) << "it names the file: " << changed.output;
}

// The job service's way: a checkpoint of this render cut short fails part way through the film, and
// the render goes on from the start (restore_failed set) to the bits of a render that never saw the
// file; a restored film's first values would change them.
TEST(Checkpoint, ADamagedCheckpointLeavesTheRenderFresh) {
  const std::string dir = test::temp_dir() + "/checkpoint_rollback", path = dir + "/c.ckpt";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  RenderParams p;
  p.width = 32, p.height = 24, p.spp = 8, p.max_depth = 3, p.threads = 2, p.adaptive = false;
  auto scene = make_render_scene(load_scene(test::own_scene("cornell.dae")), p);
  auto render = [&](bool* failed) {
    RenderSession session(*scene, p);
    Checkpointer checkpoints(path, "this render", 0);
    RenderJobEvents events;
    if (failed) events.restore_failed = [failed](const std::exception&) { *failed = true; };
    EXPECT_EQ(run_render_job(session, {}, &checkpoints, nullptr, events), StopReason::finished);
    return session.image();
  };
  const ImageRGB whole = render(nullptr);
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(bytes.size(), 1000u);
  std::ofstream(path, std::ios::binary) << bytes.substr(0, bytes.size() * 3 / 4);  // inside the film's arrays
  bool failed = false;
  const ImageRGB again = render(&failed);
  EXPECT_TRUE(failed) << "the cut file was restored";
  ASSERT_EQ(whole.pixels.size(), again.pixels.size());
  EXPECT_EQ(std::memcmp(whole.pixels.data(), again.pixels.data(), whole.pixels.size() * sizeof(whole.pixels[0])), 0)
      << "the render did not start from nothing";
}

}  // namespace
}  // namespace pt
