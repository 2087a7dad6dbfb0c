// What the error-vs-time benchmarks (convergence, scaling) share: the scene list, the
// render settings of the comparison framing, medians (flags: args.h).
#pragma once

#include <sched.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "args.h"
#include "session.h"

namespace bench {

struct BenchScene {
  std::string name;  // short label, also the cache / output file stem
  std::string path;
  int max_depth = 5;
  float lens_radius = 0, focal_distance = 4.7f;
};

// The machine the numbers come from, which every benchmark prints first: this project's hosts
// differ from run to run (2-CPU AMD EPYC with AVX2, 2-CPU Xeon with AVX-512, a 16-core device), and
// the ratios differ with them (docs/performance.md). CPUs = those this process may run on.
inline std::string host_description() {
  std::string model = "unknown CPU";
  if (FILE* f = std::fopen("/proc/cpuinfo", "r")) {
    char line[512];
    while (std::fgets(line, sizeof line, f)) {
      const char* colon = std::strchr(line, ':');
      if (std::strncmp(line, "model name", 10) != 0 || !colon) continue;
      model = colon + 1;
      model.erase(0, model.find_first_not_of(" \t"));
      model.erase(model.find_last_not_of(" \t\n") + 1);
      break;
    }
    std::fclose(f);
  }
  cpu_set_t set;
  const int cpus = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : 0;
  const char* isa = __builtin_cpu_supports("avx512f") ? "AVX-512" : __builtin_cpu_supports("avx2") ? "AVX2" : "SSE2";
  return model + ", " + (cpus > 0 ? std::to_string(cpus) : std::string("?")) + " CPUs, " + isa;
}

inline void print_host(const char* prog) { std::printf("%s: host %s\n", prog, host_description().c_str()); }

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

// The flags the error-vs-time benchmarks share; each default differs in smoke mode (dof.dae, 64x48).
struct CommonFlags {
  bool smoke;
  int spp, runs;
  std::string only;  // --scene
  pt::SamplerKind sampler;
};
inline CommonFlags common_flags(Args& args, int spp, int smoke_spp, int runs) {
  CommonFlags f;
  f.smoke = args.flag("--smoke");
  f.spp = args.integer("--spp", f.smoke ? smoke_spp : spp, 1, 1 << 24);
  f.runs = args.integer("--runs", f.smoke ? 1 : runs, 1, 1000);
  f.only = args.value("--scene", "");
  f.sampler = args.sampler();
  return f;
}

inline const char* sampler_name(pt::SamplerKind k) { return k == pt::SamplerKind::sobol ? "sobol" : "independent"; }

// One of issue 6's targets against this run: every case (a scene, a thread count) must reach
// `goal`. The verdict names the weakest case, so that a reader sees at once where this host
// stands. Values compare as the tables print them, to two decimals.
class TargetCheck {
 public:
  // `smoke`: a --smoke run, too small to measure anything; the verdict says so.
  TargetCheck(std::string what, double goal, bool smoke = false)
      : m_what(std::move(what)), m_goal(goal), m_where(smoke ? "in this smoke run (no measurement)" : "on this host") {}
  void add(double value, const std::string& label) {
    const double shown = std::round(value * 100.0) / 100.0;
    ++m_cases;
    if (!(shown >= m_goal)) ++m_below;  // NaN counts as missed
    // NaN is the worst case of all: once there, it stays the one named.
    if (m_cases == 1 || std::isnan(shown) || (!std::isnan(m_worst) && shown < m_worst))
      m_worst = shown, m_worst_label = label;
  }
  // "target: <what>: met on this host (lowest 0.72: CBspheres, 1 thread)", or "not met ... (lowest
  // 0.48: CBspheres, 1 thread; 5 of 8 cases below 0.70)".
  std::string verdict() const {
    char buf[512];
    if (m_cases == 0) {
      std::snprintf(buf, sizeof buf, "target: %s: nothing measured", m_what.c_str());
    } else if (m_below == 0) {
      std::snprintf(buf, sizeof buf, "target: %s: met %s (lowest %.2f: %s)", m_what.c_str(), m_where.c_str(), m_worst,
                    m_worst_label.c_str());
    } else {
      std::snprintf(buf, sizeof buf, "target: %s: not met %s (lowest %.2f: %s; %d of %d cases below %.2f)",
                    m_what.c_str(), m_where.c_str(), m_worst, m_worst_label.c_str(), m_below, m_cases, m_goal);
    }
    return buf;
  }

 private:
  std::string m_what;
  double m_goal;
  std::string m_where;
  int m_cases = 0, m_below = 0;
  double m_worst = 0;
  std::string m_worst_label;
};

// Seconds since `t0` on the steady clock: what the benchmarks time.
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace bench
