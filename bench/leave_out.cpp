// bench_leave_out: samples/s of the specialised vs the generic path loop, and memory per primitive
// of the shared render-scene base against the file's description.
//   bench_leave_out [runs=3] [scene.dae ...]   (defaults: course scenes in ../shared and ours)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "bench_common.h"
#include "collada.h"
#include "progress.h"
#include "session.h"

using namespace pt;
using bench::exists;
using bench::median;  // the middle two averaged: for an even runs count it used to take the upper one

namespace {

// Each run renders a view of one shared base, as the server's jobs do.
double samples_per_second(const SceneBase& base, RenderParams p, bool generic) {
  auto scene = make_view(base, p);
  if (generic) scene->features.bits = kFeatAll;  // the path loop with every feature
  RenderSession s(*scene, p);
  s.render_all();
  return s.stats().samples / s.stats().seconds;
}

// What the file's description holds for rendering: the copy the server used to cache per scene.
size_t desc_bytes(const SceneDesc& d) {
  size_t b = d.materials.size() * sizeof(Material) + d.lights.size() * sizeof(LightDesc) +
             d.spheres.size() * sizeof(SphereDesc);
  for (const MeshDesc& m : d.meshes)
    b += sizeof(MeshDesc) + (m.positions.size() + m.normals.size()) * sizeof(Vec3) +
         m.indices.size() * sizeof(uint32_t) + m.tri_material.size() * sizeof(int);
  return b;
}

const char* kUsage = "bench_leave_out [runs=3] [scene.dae ...]   (default scenes: the course's in ../shared and ours)";

}  // namespace

int main(int argc, char** argv) {
  int runs = 3;
  if (argc > 1) {
    const std::string a = argv[1];
    char* end = nullptr;
    const long v = std::strtol(a.c_str(), &end, 10);
    if (a == "-h" || a == "--help") {
      std::printf("usage: %s\n", kUsage);
      return 0;
    }
    if (a.empty() || *end != '\0' || v < 1 || v > 1000) {
      std::fprintf(stderr, "bench_leave_out: runs must be a whole number from 1 to 1000, not '%s'\nusage: %s\n", a.c_str(),
                   kUsage);
      return 2;
    }
    runs = int(v);
  }
  std::vector<std::string> scenes;
  for (int i = 2; i < argc; ++i) scenes.push_back(argv[i]);
  if (scenes.empty()) {
    std::string shared = std::string(PT_SOURCE_DIR) + "/../shared/scenes-cs184/";
    for (const char* f : {"CBspheres_lambertian.dae", "CBbunny.dae", "CBspheres.dae", "CBdragon.dae"})
      if (exists(shared + f)) scenes.push_back(shared + f);
    scenes.push_back(std::string(PT_SOURCE_DIR) + "/scenes/cornell.dae");
  }
  bench::print_host("bench_leave_out");
  // B/prim: bytes per triangle or sphere; shared: the SceneBase (Embree BVH and buffers, our
  // shading arrays, lights), file: the SceneDesc's arrays. Per-job set-up: a whole render scene
  // (make_render_scene, what a server job used to build) against a view of the shared base.
  std::printf("%-34s %-30s %12s %12s %8s %13s %11s %12s %9s\n", "scene", "features", "generic", "specialised", "ratio",
              "shared B/prim", "file B/prim", "full scene", "view");
  ProgressBar bar("bench_leave_out");
  int done = 0, total = int(scenes.size()) * runs * 2;
  for (const std::string& path : scenes) {
    SceneDesc desc;
    try {
      desc = load_collada(path);
    } catch (const std::exception& e) {  // the message names the file and what is wrong
      bar.finish();
      std::fprintf(stderr, "bench_leave_out: %s\n", e.what());
      return 1;
    }
    RenderParams p;
    p.width = 240;
    p.height = 180;
    p.spp = 16;
    p.max_depth = 5;
    p.light_samples = 1;
    p.adaptive = false;
    p.threads = 2;
    SceneBase base = make_scene_base(desc);
    std::vector<double> gen, spec, full_s, view_s;
    for (int r = 0; r < runs; ++r) {  // interleaved, so drift hits both alike
      gen.push_back(samples_per_second(base, p, true));
      bar.update(double(++done) / total);
      spec.push_back(samples_per_second(base, p, false));
      bar.update(double(++done) / total);
      auto t0 = std::chrono::steady_clock::now();
      make_render_scene(desc, p);
      auto t1 = std::chrono::steady_clock::now();
      make_view(base, p);
      auto t2 = std::chrono::steady_clock::now();
      full_s.push_back(std::chrono::duration<double>(t1 - t0).count());
      view_s.push_back(std::chrono::duration<double>(t2 - t1).count());
    }
    std::string feats;
    for (const std::string& m : base.features.materials) feats += (feats.empty() ? "" : ",") + m;
    double prims = double(std::max<size_t>(1, desc.triangle_count() + desc.spheres.size()));
    std::string name = path.substr(path.find_last_of('/') + 1);
    bar.finish();
    std::printf("%-34s %-30s %10.3f M %10.3f M %8.3f %13.1f %11.1f %9.3f ms %6.1f us\n", name.c_str(), feats.c_str(),
                median(gen) / 1e6, median(spec) / 1e6, median(spec) / median(gen), base.memory_bytes() / prims,
                desc_bytes(desc) / prims, median(full_s) * 1e3, median(view_s) * 1e6);
  }
  return 0;
}
