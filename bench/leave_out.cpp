// bench_leave_out: samples/s of the path loop's forms (specialised against generic, with and without
// packets and SIMD lanes), and memory per primitive of the shared render-scene base against the
// file's description.
//   bench_leave_out [runs=3] [scene.dae ...]   (defaults: course scenes in ../shared and ours)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "bench_common.h"
#include "collada.h"
#include "loop_forms.h"
#include "progress.h"
#include "session.h"

using namespace pt;
using bench::exists;
using bench::median;  // the middle two averaged: for an even runs count it used to take the upper one

namespace {

// The path loop's forms compared here: specialised on the scene's features (the default), with
// every feature, one path at a time instead of in Embree packets, without SIMD lanes.
enum class Form { specialised, generic, one_path, no_lanes };

// Each run renders a view of one shared base, as the server's jobs do.
double samples_per_second(const SceneBase& base, RenderParams p, Form form) {
  auto scene = make_view(base, p);
  if (form == Form::generic) scene->features.bits = kFeatAll;
  forms::Scoped forms;
  forms->packets = form != Form::one_path;
  forms->lanes = form != Form::no_lanes;
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
  // packets, lanes: samples/s with them over without (the same images).
  std::printf("%-34s %-30s %12s %12s %8s %8s %8s %13s %11s %12s %9s\n", "scene", "features", "generic", "specialised",
              "ratio", "packets", "lanes", "shared B/prim", "file B/prim", "full scene", "view");
  ProgressBar bar("bench_leave_out");
  int done = 0, total = int(scenes.size()) * runs * 4;
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
    std::vector<double> gen, spec, one, nolanes, full_s, view_s;
    for (int r = 0; r < runs; ++r) {  // interleaved, so drift hits all alike
      gen.push_back(samples_per_second(base, p, Form::generic));
      bar.update(double(++done) / total);
      spec.push_back(samples_per_second(base, p, Form::specialised));
      bar.update(double(++done) / total);
      one.push_back(samples_per_second(base, p, Form::one_path));
      bar.update(double(++done) / total);
      nolanes.push_back(samples_per_second(base, p, Form::no_lanes));
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
    std::printf("%-34s %-30s %10.3f M %10.3f M %8.3f %8.3f %8.3f %13.1f %11.1f %9.3f ms %6.1f us\n", name.c_str(),
                feats.c_str(), median(gen) / 1e6, median(spec) / 1e6, median(spec) / median(gen),
                median(spec) / median(one), median(spec) / median(nolanes), base.memory_bytes() / prims,
                desc_bytes(desc) / prims, median(full_s) * 1e3, median(view_s) * 1e6);
  }
  return 0;
}
