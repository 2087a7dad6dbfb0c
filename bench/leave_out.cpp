// bench_leave_out: samples/s of the specialised vs the generic path loop, and memory per triangle.
//   bench_leave_out [runs=3] [scene.dae ...]   (defaults: course scenes in ../shared and ours)
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "collada.h"
#include "progress.h"
#include "render.h"

using namespace pt;

namespace {

double samples_per_second(const SceneDesc& desc, RenderParams p, bool generic, size_t* bytes) {
  p.generic = generic;
  auto scene = make_render_scene(desc, p);
  if (bytes) *bytes = scene->accel->memory_bytes();
  RenderSession s(*scene, p);
  s.render_all();
  return s.stats().samples / s.stats().seconds;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

bool exists(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  std::vector<std::string> scenes;
  for (int i = 2; i < argc; ++i) scenes.push_back(argv[i]);
  if (scenes.empty()) {
    std::string shared = std::string(PT_SOURCE_DIR) + "/../shared/scenes-cs184/";
    for (const char* f : {"CBspheres_lambertian.dae", "CBbunny.dae", "CBspheres.dae", "CBdragon.dae"})
      if (exists(shared + f)) scenes.push_back(shared + f);
    scenes.push_back(std::string(PT_SOURCE_DIR) + "/scenes/cornell.dae");
  }
  std::printf("%-34s %-26s %12s %12s %8s %10s\n", "scene", "features", "generic", "specialised", "ratio", "B/tri");
  ProgressBar bar("bench_leave_out");
  int done = 0, total = int(scenes.size()) * runs * 2;
  for (const std::string& path : scenes) {
    SceneDesc desc = load_collada(path);
    RenderParams p;
    p.width = 240;
    p.height = 180;
    p.spp = 16;
    p.max_depth = 5;
    p.light_samples = 1;
    p.adaptive = false;
    p.threads = 2;
    std::vector<double> gen, spec;
    size_t bytes = 0;
    for (int r = 0; r < runs; ++r) {  // interleaved, so drift hits both alike
      gen.push_back(samples_per_second(desc, p, true, nullptr));
      bar.update(double(++done) / total);
      spec.push_back(samples_per_second(desc, p, false, &bytes));
      bar.update(double(++done) / total);
    }
    auto scene = make_render_scene(desc, p);
    std::string feats;
    for (const std::string& m : scene->features.materials) feats += (feats.empty() ? "" : ",") + m;
    size_t tris = std::max<size_t>(1, desc.triangle_count() + desc.spheres.size());
    std::string name = path.substr(path.find_last_of('/') + 1);
    bar.finish();
    std::printf("%-34s %-26s %10.3f M %10.3f M %8.3f %10.1f\n", name.c_str(), feats.c_str(), median(gen) / 1e6,
                median(spec) / 1e6, median(spec) / median(gen), double(bytes) / tris);
  }
  return 0;
}
