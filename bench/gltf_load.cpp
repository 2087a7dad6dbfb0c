// Loading a large glTF: writes a 1M-triangle .glb (a rippled grid with normals, 32-bit indices)
// into a temporary folder, then times load_scene (read, check, tinygltf, accessors -> SceneDesc)
// and make_scene_base (Embree's BVH, lights, materials) and reports the memory they take per
// triangle: the SceneDesc's arrays, the built base (SceneBase::memory_bytes), and the process's
// peak resident set over the whole load. Median of --runs loads. Target: load + build under 1 s.
//
//   ./build/bench_gltf_load [--triangles N=1000000] [--runs N=3] [--smoke]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "args.h"
#include "bench_common.h"
#include "render_scene.h"
#include "scene_file.h"

namespace {

using clock_type = std::chrono::steady_clock;
double since(clock_type::time_point t0) { return bench::seconds_since(t0); }

// Resident set now (Linux /proc/self/statm) and at its peak so far, in bytes.
size_t resident_bytes() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return size_t(resident) * size_t(sysconf(_SC_PAGESIZE));
}
size_t peak_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return size_t(u.ru_maxrss) * 1024;
}

// An n x n grid of quads (2 n^2 triangles) over [-1, 1]^2, rippled in y, as a .glb.
void write_grid_glb(const std::string& path, int n) {
  const int v = n + 1;
  std::vector<float> pos, nrm;
  pos.reserve(size_t(v) * v * 3);
  nrm.reserve(size_t(v) * v * 3);
  for (int j = 0; j < v; ++j)
    for (int i = 0; i < v; ++i) {
      float x = 2.0f * i / n - 1, z = 2.0f * j / n - 1;
      float y = 0.05f * std::sin(12 * x) * std::cos(9 * z);
      float dx = 0.6f * std::cos(12 * x) * std::cos(9 * z), dz = -0.45f * std::sin(12 * x) * std::sin(9 * z);
      float len = std::sqrt(dx * dx + 1 + dz * dz);
      pos.insert(pos.end(), {x, y, z});
      nrm.insert(nrm.end(), {-dx / len, 1 / len, -dz / len});
    }
  std::vector<uint32_t> idx;
  idx.reserve(size_t(n) * n * 6);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      uint32_t a = uint32_t(j * v + i), b = a + 1, c = a + uint32_t(v), d = c + 1;
      idx.insert(idx.end(), {a, c, b, b, c, d});
    }
  const size_t pb = pos.size() * 4, nb = nrm.size() * 4, ib = idx.size() * 4;
  char json[2048];
  std::snprintf(json, sizeof json,
                R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
                R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1},"indices":2,"material":0}]}],)"
                R"("materials":[{"pbrMetallicRoughness":{"metallicFactor":0}}],)"
                R"("accessors":[{"bufferView":0,"componentType":5126,"count":%zu,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]},)"
                R"({"bufferView":1,"componentType":5126,"count":%zu,"type":"VEC3"},)"
                R"({"bufferView":2,"componentType":5125,"count":%zu,"type":"SCALAR"}],)"
                R"("bufferViews":[{"buffer":0,"byteLength":%zu},{"buffer":0,"byteOffset":%zu,"byteLength":%zu},)"
                R"({"buffer":0,"byteOffset":%zu,"byteLength":%zu}],"buffers":[{"byteLength":%zu}]})",
                pos.size() / 3, nrm.size() / 3, idx.size(), pb, pb, nb, pb + nb, ib, pb + nb + ib);
  std::string j = json;
  while (j.size() % 4) j += ' ';
  const uint32_t bin = uint32_t(pb + nb + ib), total = uint32_t(12 + 8 + j.size() + 8 + bin);
  std::ofstream out(path, std::ios::binary);
  auto u32 = [&](uint32_t x) { out.write(reinterpret_cast<const char*>(&x), 4); };
  out.write("glTF", 4), u32(2), u32(total);
  u32(uint32_t(j.size())), out.write("JSON", 4), out.write(j.data(), std::streamsize(j.size()));
  u32(bin), out.write("BIN\0", 4);
  out.write(reinterpret_cast<const char*>(pos.data()), std::streamsize(pb));
  out.write(reinterpret_cast<const char*>(nrm.data()), std::streamsize(nb));
  out.write(reinterpret_cast<const char*>(idx.data()), std::streamsize(ib));
  if (!out) throw std::runtime_error(path + ": cannot write");
}

}  // namespace

int main(int argc, char** argv) {
  bench::Args args(argc, argv, "bench_gltf_load [--triangles N=1000000] [--runs N=3] [--smoke]");
  if (args.help()) return 0;
  const bool smoke = args.flag("--smoke");
  const int triangles = args.integer("--triangles", smoke ? 20000 : 1000000, 2, 50000000);
  const int runs = args.integer("--runs", smoke ? 1 : 3, 1, 100);
  args.finish();
  return bench::run_guarded(args.prog.c_str(), [&] {
    bench::print_host("bench_gltf_load");
    const int n = std::max(1, int(std::ceil(std::sqrt(triangles / 2.0))));
    char dir_template[] = "/tmp/bench_gltf_load.XXXXXX";
    if (!mkdtemp(dir_template)) throw std::runtime_error("cannot make a temporary folder");
    const std::string path = std::string(dir_template) + "/grid.glb";
    // Written by a child process: its arrays must not count in this process's peak.
    pid_t child = fork();
    if (child == 0) {
      try {
        write_grid_glb(path, n);
      } catch (...) {
        _exit(1);
      }
      _exit(0);
    }
    int status = 0;
    if (child < 0 || waitpid(child, &status, 0) != child || status != 0) throw std::runtime_error("cannot write " + path);
    std::ifstream size_probe(path, std::ios::binary | std::ios::ate);
    const double file_mb = double(size_probe.tellg()) / 1048576.0;

    std::vector<double> load_s, build_s;
    size_t desc_bytes = 0, base_bytes = 0, tris = 0, peak_growth = 0;
    for (int r = 0; r < runs; ++r) {
      const size_t before = resident_bytes();
      auto t0 = clock_type::now();
      pt::SceneDesc desc = pt::load_scene(path);
      load_s.push_back(since(t0));
      t0 = clock_type::now();
      pt::SceneBase base = pt::make_scene_base(desc);
      build_s.push_back(since(t0));
      if (r == 0) {
        peak_growth = peak_bytes() > before ? peak_bytes() - before : 0;
        tris = desc.triangle_count();
        for (const pt::MeshDesc& m : desc.meshes)
          desc_bytes += m.positions.size() * sizeof(pt::Vec3) + m.normals.size() * sizeof(pt::Vec3) +
                        m.indices.size() * sizeof(uint32_t) + m.tri_material.size() * sizeof(int);
        base_bytes = base.memory_bytes();
      }
    }
    std::remove(path.c_str());
    rmdir(dir_template);
    using bench::median;
    const double total = median(load_s) + median(build_s);
    std::printf("glTF load: %zu triangles, %.1f MB .glb, median of %d runs\n", tris, file_mb, runs);
    std::printf("load_scene (read, check, tinygltf, SceneDesc)  %8.3f s\n", median(load_s));
    std::printf("make_scene_base (BVH, lights, materials)       %8.3f s\n", median(build_s));
    std::printf("load + build                                   %8.3f s  (%.2f us a triangle)\n", total, 1e6 * total / double(tris));
    std::printf("SceneDesc arrays                               %8.1f bytes a triangle\n", double(desc_bytes) / double(tris));
    std::printf("built base (BVH, vertices, shading data)       %8.1f bytes a triangle\n", double(base_bytes) / double(tris));
    std::printf("peak resident growth over the first load      %8.1f bytes a triangle\n", double(peak_growth) / double(tris));
    bench::TargetCheck target("a 1M-triangle glTF loaded and built in under 1 s: M triangles/s", 1.0, smoke);
    target.add(double(tris) / 1e6 / total, "grid");
    std::printf("%s\n", target.verdict().c_str());
    return 0;
  });
}
