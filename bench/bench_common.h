// What the error-vs-time benchmarks (convergence, ceiling, scaling) share: the scene list, the
// render settings of the comparison framing, flags, medians.
#pragma once

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "render.h"

namespace bench {

struct BenchScene {
  std::string name;  // short label, also the cache / output file stem
  std::string path;
  int max_depth = 5;
  float lens_radius = 0, focal_distance = 4.7f;
};

inline bool exists(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

// CBspheres (m = 100), CBbunny, CBdragon (m = 5) from ../shared/scenes-cs184 and our dof.dae
// (thin lens 0.12, focus 4.7, m = 5). Prints one skip line when the course scenes are absent.
// `only`: keep the scenes whose name contains it (empty: all; none matching exits 2). Smoke mode:
// dof.dae only.
inline std::vector<BenchScene> bench_scenes(const char* prog, bool smoke, const std::string& only) {
  std::vector<BenchScene> out;
  const std::string own = std::string(PT_SOURCE_DIR) + "/scenes/";
  BenchScene dof{"dof", own + "dof.dae", 5, 0.12f, 4.7f};
  if (smoke) return {dof};
  const std::string shared = std::string(PT_SOURCE_DIR) + "/../shared/scenes-cs184/";
  if (exists(shared)) {
    out.push_back({"CBspheres", shared + "CBspheres.dae", 100});
    out.push_back({"CBbunny", shared + "CBbunny.dae", 5});
    out.push_back({"CBdragon", shared + "CBdragon.dae", 5});
  } else {
    std::printf("%s: skipping CBspheres, CBbunny, CBdragon: ../shared/scenes-cs184 is absent\n", prog);
  }
  out.push_back(dof);
  if (only.empty()) return out;
  std::vector<BenchScene> kept;
  std::string names;
  for (const BenchScene& s : out) {
    if (s.name.find(only) != std::string::npos) kept.push_back(s);
    names += (names.empty() ? "" : ", ") + s.name;
  }
  if (kept.empty()) {  // an empty table would read as a result
    std::fprintf(stderr, "%s: --scene '%s' matches none of: %s\n", prog, only.c_str(), names.c_str());
    std::exit(2);
  }
  return kept;
}

// The comparison framing: the course's 800x600 view scaled to 480x360 (keep_fov), one
// light sample, no adaptive sampling, 2 threads. Smoke mode: 64x48.
inline pt::RenderParams bench_params(const BenchScene& s, bool smoke) {
  pt::RenderParams p;
  p.width = smoke ? 64 : 480;
  p.height = smoke ? 48 : 360;
  p.keep_fov = true;
  p.light_samples = 1;
  p.adaptive = false;
  p.threads = 2;
  p.max_depth = s.max_depth;
  p.lens_radius = s.lens_radius;
  p.focal_distance = s.focal_distance;
  return p;
}

inline const char* sampler_name(pt::SamplerKind k) { return k == pt::SamplerKind::sobol ? "sobol" : "independent"; }

inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Minimal flag reading: `--name value` and `--name` switches; unknown flags end the program.
struct Args {
  int argc;
  char** argv;
  std::vector<bool> used;
  Args(int c, char** v) : argc(c), argv(v), used(size_t(c), false) {}
  bool flag(const char* name) {
    for (int i = 1; i < argc; ++i)
      if (!std::strcmp(argv[i], name)) return used[size_t(i)] = true;
    return false;
  }
  std::string value(const char* name, const std::string& def) {
    for (int i = 1; i + 1 < argc; ++i)
      if (!std::strcmp(argv[i], name)) {
        used[size_t(i)] = used[size_t(i) + 1] = true;
        return argv[i + 1];
      }
    return def;
  }
  int integer(const char* name, int def) { return std::atoi(value(name, std::to_string(def)).c_str()); }
  // --sampler sobol|independent (default: the renderer's default); exits 2 on anything else.
  pt::SamplerKind sampler() {
    std::string v = value("--sampler", "default");
    if (v == "default") return pt::RenderParams().sampler;
    if (v == "sobol") return pt::SamplerKind::sobol;
    if (v == "independent") return pt::SamplerKind::independent;
    std::fprintf(stderr, "%s: --sampler must be sobol or independent, not '%s'\n", argv[0], v.c_str());
    std::exit(2);
  }
  // Call after reading every flag: exits 2 naming the first one not understood.
  void finish(const char* usage) {
    for (int i = 1; i < argc; ++i)
      if (!used[size_t(i)]) {
        std::fprintf(stderr, "%s: unknown argument '%s'\nusage: %s\n", argv[0], argv[i], usage);
        std::exit(2);
      }
  }
};

}  // namespace bench
