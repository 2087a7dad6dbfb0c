// bench_convergence: error against run time. Per scene it renders (once, cached) a high-spp
// reference with our renderer, then renders progressively (1, 2, 4, ... spp) and logs per pass the
// rendering seconds, the true relMSE and RMSE against the reference and the session's own error
// estimate, and the estimate over the truth; writes a CSV and a log-log plot per scene and prints
// the efficiency 1 / (relMSE x seconds), samples/s and rays/s, and a verdict line on the estimate
// staying within 1.5x of the truth from 16 spp. Numbers only: it asserts nothing about speed.
//
//   bench_convergence [--spp 256] [--ref-spp 1024] [--runs 3] [--scene NAME] [--sampler sobol|independent] [--depth M] [--out DIR]
//                     [--cache DIR] [--rebuild-ref] [--smoke]
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench_common.h"
#include "collada.h"
#include "plot.h"
#include "progress.h"
#include "session.h"

using namespace pt;
using namespace bench;

namespace {

const char* kUsage =
    "bench_convergence [--spp N=256] [--ref-spp N=1024] [--runs N=3] [--scene NAME] [--sampler sobol|independent] [--depth M] [--out DIR] [--cache DIR] "
    "[--rebuild-ref] [--smoke]";
constexpr int kReferenceVersion = 2;      // bump when the reference's meaning changes
constexpr uint64_t kReferenceSeed = 7919;  // the measured runs use seed 0: independent noise

uint64_t fnv1a_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

void make_dirs(const std::string& dir) {
  for (size_t i = 1; i <= dir.size(); ++i)
    if (i == dir.size() || dir[i] == '/') mkdir(dir.substr(0, i).c_str(), 0755);
}

struct Reference {
  ImageRGB image;
  double error_estimate = 0;  // its own estimated relMSE: the floor under every measured error
  double seconds = 0;
  bool cached = false;
};

// The reference for these parameters: read from the cache, or rendered (with a progress bar)
// and stored there. The key covers the scene file's bytes and every parameter that changes it.
Reference reference_for(const BenchScene& sc, const SceneDesc& desc, RenderParams p, const std::string& cache,
                        bool rebuild) {
  p.seed = kReferenceSeed;
  // Independent samples for the reference whatever the runs use: the plainest unbiased estimator,
  // so a bias in a smarter sampler would show up against it.
  p.sampler = SamplerKind::independent;
  char key[256];
  std::snprintf(key, sizeof key, "%s_%016llx_%dx%d_kf%d_m%d_l%d_b%g_d%g_s%d_%s_seed%llu_v%d", sc.name.c_str(),
                static_cast<unsigned long long>(fnv1a_file(sc.path)), p.width, p.height, int(p.keep_fov), p.max_depth,
                p.light_samples, p.lens_radius, p.focal_distance, p.spp, sampler_name(p.sampler),
                static_cast<unsigned long long>(p.seed),
                kReferenceVersion);
  std::string exr = cache + "/" + key + ".exr", info = cache + "/" + key + ".txt";
  Reference ref;
  if (!rebuild && exists(exr) && exists(info)) {
    std::ifstream in(info);
    if (in >> ref.error_estimate >> ref.seconds) {
      ref.image = read_image(exr);
      if (ref.image.width == p.width && ref.image.height == p.height) {
        ref.cached = true;
        return ref;
      }
    }
  }
  auto scene = make_render_scene(desc, p);
  RenderSession s(*scene, p);
  ProgressBar bar("reference " + sc.name + " " + std::to_string(p.spp) + " spp");
  s.render_all(nullptr, [&] { bar.update(s.progress()); });
  bar.finish();
  ref.image = s.image();
  ref.error_estimate = s.error_estimate();
  ref.seconds = s.stats().seconds;
  make_dirs(cache);
  write_image(ref.image, exr, {{"bench:key", key}});
  std::ofstream(info) << ref.error_estimate << " " << ref.seconds << "\n";
  return ref;
}

struct PassRow {
  int spp = 0;
  double seconds = 0;  // median over runs of the rendering time so far
  uint64_t samples = 0, rays = 0;
  double rel_mse = 0, rmse = 0, estimate = 0;
};

}  // namespace

int bench_main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // lines appear as they are measured, also into a file
  Args args(argc, argv, kUsage);
  if (args.help()) return 0;
  const auto [smoke, spp, runs, only, sampler] = common_flags(args, 256, 4, 3);
  const int ref_spp = args.integer("--ref-spp", smoke ? 256 : 1024, 1, 1 << 24);
  const int depth = args.integer("--depth", -1, -1, 1000000);  // overrides every scene's max depth
  const std::string out_dir = args.value("--out", std::string(PT_BINARY_DIR) + "/bench-results");
  const std::string cache = args.value("--cache", std::string(PT_BINARY_DIR) + "/bench-cache");
  const bool rebuild = args.flag("--rebuild-ref");
  args.finish();

  std::vector<BenchScene> scenes = bench_scenes("bench_convergence", smoke, only);
  make_dirs(out_dir);
  print_host("bench_convergence");
  std::printf("bench_convergence: %s, keep_fov, light_samples 1, no adaptive sampling, 2 threads, %s sampler; %d spp "
              "against a %d-spp reference (independent sampler); seconds are the median of %d run(s)\n",
              smoke ? "64x48" : "480x360", sampler_name(sampler), spp, ref_spp, runs);
  std::vector<std::string> summary;
  // The estimate against the truth (relMSE less the reference's own noise), as the issue's
  // factor 1.5: min(est/true, true/est) >= 1/1.5 on every pass from 16 spp (the first passes
  // read high with the Sobol sampler: docs/performance.md, "Error estimate").
  TargetCheck within_1p5("the estimate within 1.5x of the true error from 16 spp, min(est/true, true/est) >= 0.67",
                         0.67, smoke);
  for (const BenchScene& sc : scenes) {
    SceneDesc desc = load_collada(sc.path);
    RenderParams p = bench_params(sc, smoke);
    p.sampler = sampler;
    if (depth >= 0) p.max_depth = depth;
    p.spp = ref_spp;
    Reference ref = reference_for(sc, desc, p, cache, rebuild);
    std::printf("%s: reference %d spp (%s, %.1f s), its own estimated relMSE %.3g\n", sc.name.c_str(), ref_spp,
                ref.cached ? "cached" : "rendered", ref.seconds, ref.error_estimate);

    p.spp = spp;
    p.seed = 0;
    auto scene = make_render_scene(desc, p);
    std::vector<PassRow> rows;
    std::vector<std::vector<double>> pass_seconds;
    std::vector<double> total_seconds;
    for (int r = 0; r < runs; ++r) {
      RenderSession s(*scene, p);
      size_t k = 0;
      run_progressive(s, RunLimits(), nullptr, {}, [&](const PassReport& rep) {
        if (r == 0) {  // the images are identical across runs (per-pixel seeds): measure once
          ImageRGB img = s.image();
          PassRow row;
          row.spp = rep.target_spp;
          row.samples = s.stats().samples;
          row.rays = s.stats().rays;
          row.rel_mse = relative_mse(img, ref.image);
          row.rmse = pt::rmse(img, ref.image);
          row.estimate = rep.error;
          rows.push_back(row);
          pass_seconds.emplace_back();
        }
        if (k < pass_seconds.size()) pass_seconds[k].push_back(rep.seconds);
        ++k;
      });
    }
    for (size_t k = 0; k < rows.size(); ++k) rows[k].seconds = median(pass_seconds[k]);

    // CSV and plot.
    const std::string stem = out_dir + "/convergence_" + sc.name + "_m" + std::to_string(p.max_depth) + "_" +
                             sampler_name(sampler);
    std::string csv_path = stem + ".csv";
    if (FILE* f = std::fopen(csv_path.c_str(), "w")) {
      std::fprintf(f, "scene,max_depth,spp,seconds,samples,rays,rel_mse,rmse,error_estimate,reference_rel_mse_estimate,"
                      "efficiency\n");
      for (const PassRow& row : rows)
        std::fprintf(f, "%s,%d,%d,%.6g,%llu,%llu,%.6g,%.6g,%.6g,%.6g,%.6g\n", sc.name.c_str(), p.max_depth, row.spp,
                     row.seconds, static_cast<unsigned long long>(row.samples),
                     static_cast<unsigned long long>(row.rays), row.rel_mse, row.rmse, row.estimate,
                     ref.error_estimate, 1.0 / (row.rel_mse * row.seconds));
      std::fclose(f);
    }
    Series truth{"TRUE RELMSE", {0.85f, 0.1f, 0.1f}}, est{"ESTIMATE", {0.1f, 0.3f, 0.9f}},
        floor{"REFERENCE NOISE", {0.45f, 0.45f, 0.45f}, true};
    for (const PassRow& row : rows) {
      truth.x.push_back(row.seconds);
      truth.y.push_back(row.rel_mse);
      est.x.push_back(row.seconds);
      est.y.push_back(row.estimate);
    }
    if (!rows.empty()) {
      floor.x = {rows.front().seconds, rows.back().seconds};
      floor.y = {ref.error_estimate, ref.error_estimate};
    }
    std::string png_path = stem + ".png";
    write_image(loglog_plot(sc.name + " M=" + std::to_string(p.max_depth) + " " + sampler_name(sampler) +
                                ": RELMSE VS SECONDS (2 THREADS)",
                            "SECONDS", "RELMSE", {truth, est, floor}),
                png_path);

    // Per-pass log.
    std::printf("%-10s %6s %9s %11s %10s %10s %10s %10s %8s %11s\n", "scene", "spp", "seconds", "rays/sample",
                "relMSE", "RMSE", "estimate", "ref floor", "est/true", "efficiency");
    for (const PassRow& row : rows) {
      // NaN where the truth is lost in the reference's noise, or before any pixel has two samples.
      const double truth = row.rel_mse - ref.error_estimate;
      const double ratio = truth > 0 && std::isfinite(row.estimate) ? row.estimate / truth : NAN;
      std::printf("%-10s %6d %9.3f %11.2f %10.4g %10.4g %10.4g %10.3g %8.2f %11.1f\n", sc.name.c_str(), row.spp,
                  row.seconds, double(row.rays) / std::max<uint64_t>(1, row.samples), row.rel_mse, row.rmse,
                  row.estimate, ref.error_estimate, ratio, 1.0 / (row.rel_mse * row.seconds));
      if (row.spp >= 16)
        within_1p5.add(std::min(ratio, 1 / ratio), sc.name + ", " + std::to_string(row.spp) + " spp");
    }
    std::printf("wrote %s and %s\n\n", csv_path.c_str(), png_path.c_str());

    const PassRow& last = rows.back();
    double eff64 = NAN;
    for (const PassRow& row : rows)
      if (row.spp == 64) eff64 = 1.0 / (row.rel_mse * row.seconds);
    char line[512];
    std::snprintf(line, sizeof line, "%-10s %4d %5d %9.2f %8.3f M %8.2f M %8.2f %10.3g %10.3g %10.3g %9.1f %9.1f",
                  sc.name.c_str(), p.max_depth, last.spp, last.seconds, last.samples / last.seconds / 1e6,
                  last.rays / last.seconds / 1e6, double(last.rays) / last.samples, last.rel_mse, last.estimate,
                  ref.error_estimate, eff64, 1.0 / (last.rel_mse * last.seconds));
    summary.push_back(line);
  }
  std::printf("%-10s %4s %5s %9s %10s %10s %8s %10s %10s %10s %9s %9s\n", "scene", "m", "spp", "seconds", "samples/s",
              "rays/s", "rays/spl", "relMSE", "estimate", "ref floor", "eff@64", "eff@final");
  for (const std::string& l : summary) std::printf("%s\n", l.c_str());
  std::printf("efficiency = 1 / (true relMSE x seconds), the reference's noise not subtracted\n");
  std::printf("%s\n", within_1p5.verdict().c_str());
  return 0;
}

int main(int argc, char** argv) { return run_guarded("bench_convergence", [&] { return bench_main(argc, argv); }); }
