// bench_scaling: samples/s of the path tracer with 1 and N threads (N = 2 unless --threads says
// otherwise) and their ratio, in the framing (480x360 keep_fov, light_samples 1, no
// adaptive sampling). Numbers only.
//
//   bench_scaling [--spp 16] [--runs 3] [--threads N] [--scene NAME] [--sampler sobol|independent] [--depth M] [--smoke]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_common.h"
#include "collada.h"
#include "progress.h"
#include "session.h"

using namespace pt;
using namespace bench;

namespace {
const char* kUsage = "bench_scaling [--spp N=16] [--runs N=3] [--threads N=2] [--scene NAME] [--sampler sobol|independent] [--depth M] [--smoke]";
}

int bench_main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // lines appear as they are measured, also into a file
  Args args(argc, argv, kUsage);
  if (args.help()) return 0;
  const auto [smoke, spp, runs, only, sampler] = common_flags(args, 16, 2, 3);
  const int depth = args.integer("--depth", -1, -1, 1000000);  // overrides every scene's max depth
  const int many = args.integer("--threads", 2, 2, 1024);
  args.finish();

  std::vector<BenchScene> scenes = bench_scenes("bench_scaling", smoke, only);
  print_host("bench_scaling");
  std::printf("bench_scaling: one %d-spp pass at %s (keep_fov, light_samples 1, no adaptive, %s sampler), median of "
              "%d runs\n",
              spp, smoke ? "64x48" : "480x360", sampler_name(sampler), runs);
  std::vector<std::string> table;
  // Issue 6 asks 2 threads for at least 1.85x one thread: 0.925 of perfect scaling, asked of N too.
  char goal_text[96];
  const double goal = std::round(0.925 * many * 100.0) / 100.0;
  std::snprintf(goal_text, sizeof goal_text, "%dt/1t >= %.2f on every scene", many, goal);
  TargetCheck target(goal_text, goal, smoke);
  ProgressBar bar("bench_scaling");
  int done = 0;
  const int total = int(scenes.size()) * runs * 2;
  for (const BenchScene& sc : scenes) {
    SceneDesc desc = load_collada(sc.path);
    RenderParams p = bench_params(sc, smoke);
    p.sampler = sampler;
    if (depth >= 0) p.max_depth = depth;
    p.spp = spp;
    auto scene = make_render_scene(desc, p);
    std::vector<double> sps[2], rps[2], busy[2], per_cpu[2];
    for (int r = 0; r < runs; ++r)
      for (int t = 0; t < 2; ++t) {  // interleaved, so drift hits both alike
        RenderParams pt = p;
        pt.threads = t == 0 ? 1 : many;
        RenderSession s(*scene, pt);
        s.render_pass(spp);
        sps[t].push_back(s.stats().samples / s.stats().seconds);
        rps[t].push_back(s.stats().rays / s.stats().seconds);
        busy[t].push_back(s.stats().cpu_seconds / (pt.threads * s.stats().seconds));
        per_cpu[t].push_back(s.stats().samples / s.stats().cpu_seconds);
        bar.update(double(++done) / total);
      }
    // Each run's N-thread rate over the 1-thread rate just before it, then the median: pairs cancel
    // the machine's slow drift, which a ratio of two medians does not; min-max shows the spread.
    std::vector<double> paired, paired_cpu;
    for (int r = 0; r < runs; ++r) {
      paired.push_back(sps[1][size_t(r)] / sps[0][size_t(r)]);
      paired_cpu.push_back(per_cpu[1][size_t(r)] / per_cpu[0][size_t(r)]);
    }
    const auto [lo, hi] = std::minmax_element(paired.begin(), paired.end());
    char line[256];
    std::snprintf(line, sizeof line, "%-10s %4d %10.3f M %10.3f M %7.2f %4.2f-%4.2f %10.2f M %10.2f M %8.2f %8.2f %9.2f",
                  sc.name.c_str(), p.max_depth, median(sps[0]) / 1e6, median(sps[1]) / 1e6, median(paired), *lo, *hi,
                  median(rps[0]) / 1e6, median(rps[1]) / 1e6, median(busy[0]), median(busy[1]), median(paired_cpu));
    table.push_back(line);
    target.add(median(paired), sc.name);
  }
  bar.finish();
  const std::string n = std::to_string(many) + "t";
  std::printf("%-10s %4s %12s %12s %7s %9s %12s %12s %8s %8s %9s\n", "scene", "m", "samples/s 1t", ("samples/s " + n).c_str(),
              (n + "/1t").c_str(), "min-max", "rays/s 1t", ("rays/s " + n).c_str(), "busy 1t", ("busy " + n).c_str(), "per-CPU");
  for (const std::string& l : table) std::printf("%s\n", l.c_str());
  std::printf("%s/1t = median over runs of the %d-thread samples/s over the 1-thread samples/s of the same run "
              "(min-max: the smallest and largest of those runs); busy = the render threads' CPU time over threads x wall "
              "time (below 1: threads waited for a core, or for each other at the pass's end); per-CPU = the same paired "
              "ratio of samples per CPU-second (1.00: the threads do not slow each other down)\n",
              n.c_str(), many);
  std::printf("%s\n", target.verdict().c_str());
  return 0;
}

int main(int argc, char** argv) { return run_guarded("bench_scaling", [&] { return bench_main(argc, argv); }); }
