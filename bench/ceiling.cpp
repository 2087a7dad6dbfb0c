// bench_ceiling: how fast Embree alone traces the rays our path tracer casts. Records every ray
// of one 16-spp pass (record_rays_on_this_thread, renderer/accel.h), then replays the list in a
// tight loop with 1 and N threads (N = 2 unless --threads says otherwise; the list split in N
// parts) six ways: through Accel::intersect / occluded (our wrapper, hit refinement included),
// through Accel::intersect_many / occluded_many (the same in Embree packets of the CPU's native
// width, what the path tracer calls), raw rtcIntersect1 / rtcOccluded1, Embree's stream API
// (rtcIntersect1M / rtcOccluded1M), and raw packets of 16 (rtcIntersect16 / rtcOccluded16, as
// Mitsuba 3's LLVM variants trace on AVX-512) and of 8 (rtcIntersect8 / rtcOccluded8). The path
// tracer's own rays/s on the same pass over the replay's is the share of its time the ray queries
// would take if nothing else cost anything. Beside it, with one thread, the same ratio for a
// minimal path loop on the same pixels (bench/minimal_loop.h): what a loop that keeps only its rays
// reaches against the raw replay of those rays; and the same loop with its own work in AVX2 lanes
// (bench/minimal_loop_lanes.h), its rays once through Accel's Ray and SurfaceHit records and once
// kept in Embree's packet layout: what an integrator rewritten in lanes could reach.
//
//   bench_ceiling [--spp 16] [--runs 5] [--threads N] [--scene NAME] [--sampler sobol|independent] [--smoke]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "bench_common.h"
#include "collada.h"
#include "minimal_loop.h"
#include "minimal_loop_lanes.h"
#include "progress.h"
#include "session.h"

using namespace pt;
using namespace bench;

namespace {

const char* kUsage = "bench_ceiling [--spp N=16] [--runs N=5] [--threads N=2] [--batch N=256] [--scene NAME] [--sampler sobol|independent] [--smoke]";

enum class Mode { accel, accel_many, raw, stream, packet16, packet8 };

size_t replay(const Accel& a, const RayRecorder& rec, size_t begin, size_t end, Mode mode, size_t batch) {
  const Ray* rays = rec.rays.data();
  const uint8_t* shadow = rec.shadow.data();
  if (mode == Mode::raw) return a.cast_raw(rays + begin, shadow + begin, end - begin, Accel::RawMode::single, 1);
  if (mode == Mode::stream) return a.cast_raw(rays + begin, shadow + begin, end - begin, Accel::RawMode::stream, batch);
  if (mode == Mode::packet16)
    return a.cast_raw(rays + begin, shadow + begin, end - begin, Accel::RawMode::packet16, 16);
  if (mode == Mode::packet8) return a.cast_raw(rays + begin, shadow + begin, end - begin, Accel::RawMode::packet8, 8);
  size_t hits = 0;
  if (mode == Mode::accel_many) {  // runs of up to 256 rays of a kind, as the path tracer's pool casts them
    constexpr size_t kRun = 256;
    std::vector<SurfaceHit> found_hits(kRun);
    std::vector<uint8_t> found(kRun);
    for (size_t i = begin; i < end;) {
      size_t j = i;
      while (j < end && j - i < kRun && shadow[j] == shadow[i]) ++j;
      if (shadow[i]) a.occluded_many(rays + i, j - i, found.data());
      else a.intersect_many(rays + i, j - i, found_hits.data(), found.data());
      for (size_t k = 0; k < j - i; ++k) hits += found[k];
      i = j;
    }
    return hits;
  }
  SurfaceHit h;
  for (size_t i = begin; i < end; ++i) hits += shadow[i] ? a.occluded(rays[i]) : a.intersect(rays[i], h);
  return hits;
}

// Rays per second of one replay of the whole list with `threads` threads.
double replay_rate(const Accel& a, const RayRecorder& rec, int threads, Mode mode, size_t batch) {
  const size_t n = rec.rays.size();
  std::vector<size_t> hits(size_t(threads), 0);
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t)
    pool.emplace_back([&, t] { hits[size_t(t)] = replay(a, rec, n * t / threads, n * (t + 1) / threads, mode, batch); });
  hits[0] = replay(a, rec, 0, n / threads, mode, batch);
  for (auto& th : pool) th.join();
  double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  static std::atomic<size_t> sink{0};
  for (size_t h : hits) sink += h;
  return double(n) / sec;
}

}  // namespace

int bench_main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // lines appear as they are measured, also into a file
  Args args(argc, argv, kUsage);
  if (args.help()) return 0;
  const auto [smoke, spp, runs, only, sampler] = common_flags(args, 16, 2, 5);
  const size_t batch = size_t(args.integer("--batch", 256, 2, 1 << 20));
  const int many = args.integer("--threads", 2, 2, 1024);
  args.finish();

  std::vector<BenchScene> scenes = bench_scenes("bench_ceiling", smoke, only);
  print_host("bench_ceiling");
  std::printf("bench_ceiling: rays of one %d-spp pass at %s (keep_fov, m = 5, light_samples 1, no adaptive), "
              "%s sampler, replayed; rays/s are medians of %d runs\n",
              spp, smoke ? "64x48" : "480x360", sampler_name(sampler), runs);
  std::vector<std::string> table, split, minimal, lanes_table;
  TargetCheck target("PT/raw >= 0.70 on every scene, with 1 and " + std::to_string(many) + " threads", 0.70, smoke);
  int packet_width = 0;  // Accel's, the same for every scene (Embree's native width)
  ProgressBar bar("bench_ceiling");
  int done = 0;
  const bool lanes_loop = simd::use_avx2();
  const int total = int(scenes.size()) * (2 * 7 + 2 + (lanes_loop ? 4 : 0)) * runs;
  for (BenchScene sc : scenes) {
    sc.max_depth = 5;
    SceneDesc desc = load_collada(sc.path);
    RenderParams p = bench_params(sc, smoke);
    p.sampler = sampler;
    p.spp = spp;
    auto scene = make_render_scene(desc, p);

    // Record on this thread: a one-thread session renders on the calling thread.
    RayRecorder rec;
    uint64_t pt_rays = 0, pt_samples = 0;
    {
      RenderParams p1 = p;
      p1.threads = 1;
      RenderSession s(*scene, p1);
      record_rays_on_this_thread(&rec);
      s.render_pass(spp);
      record_rays_on_this_thread(nullptr);
      pt_rays = s.stats().rays;
      pt_samples = s.stats().samples;
    }
    // The session also counts the camera rays of pixels it knows see only background
    // (RenderSession::find_scene_rectangle), which never reach Accel. PT rays/s below counts the
    // rays that do, so that PT and the replays measure the same work.
    if (pt_rays < rec.rays.size())
      std::printf("%s: warning: the session counted %llu rays, the recorder saw %zu\n", sc.name.c_str(),
                  static_cast<unsigned long long>(pt_rays), rec.rays.size());
    else if (pt_rays > rec.rays.size())
      std::printf("%s: %.1f%% of the session's rays are background camera rays answered without a query\n",
                  sc.name.c_str(), 100.0 * double(pt_rays - rec.rays.size()) / double(pt_rays));
    size_t shadows = 0;
    for (uint8_t s : rec.shadow) shadows += s;

    const Accel& accel = *scene->accel;
    packet_width = accel.packet_width();
    // The minimal loop's own rays, recorded the same way.
    const std::vector<int> pixels = scene_pixels(*scene, p);
    RayRecorder minimal_rec;
    record_rays_on_this_thread(&minimal_rec);
    const double minimal_radiance = minimal_loop_pass(*scene, pixels, p.width, p.height, spp).radiance;
    record_rays_on_this_thread(nullptr);
    size_t minimal_shadows = 0;
    for (uint8_t s : minimal_rec.shadow) minimal_shadows += s;
    std::vector<double> minimal_ratio;
    AccelTimer minimal_timer;
    uint64_t minimal_ticks = 0, minimal_rays = 0;
    // The lanes loops' rays (records, then in place): the same paths with other random numbers.
    struct LanesLoop {
      bool in_place = false;
      RayRecorder rec;
      double radiance = 0;
      std::vector<double> ratio;
      AccelTimer timer;
      uint64_t ticks = 0, rays = 0;
    };
    LanesLoop lanes_loops[2];
    lanes_loops[1].in_place = true;
    for (LanesLoop& l : lanes_loops) {
      if (!lanes_loop) break;
      MinimalLoopResult result;
      record_rays_on_this_thread(&l.rec);
      minimal_loop_lanes_pass(*scene, pixels, p.width, p.height, spp, result, l.in_place);
      record_rays_on_this_thread(nullptr);
      l.radiance = result.radiance;
    }
    double pt_rest_per_ray = 0;
    for (Mode m : {Mode::accel, Mode::accel_many, Mode::raw, Mode::stream, Mode::packet16, Mode::packet8})
      replay_rate(accel, rec, 1, m, batch);  // warm up
    for (int threads : {1, many}) {
      std::vector<double> pt_rate, acc, acc_many, raw, stream, packet, packet8;
      // One thread renders and replays on this thread, where AccelTimer sees every Embree call.
      const bool timed = threads == 1;
      AccelTimer pt_timer, raw_timer;
      uint64_t pt_ticks = 0, raw_ticks = 0;
      const Mode raw_mode = !p.ray_packets ? Mode::raw : packet_width == 16 ? Mode::packet16 : Mode::packet8;
      for (int r = 0; r < runs; ++r) {  // interleaved, so drift hits every column alike
        RenderParams pt = p;
        pt.threads = threads;
        RenderSession s(*scene, pt);
        if (timed) time_accel_on_this_thread(&pt_timer);
        const uint64_t t0 = accel_ticks();
        s.render_pass(spp);
        if (timed) pt_ticks += accel_ticks() - t0;
        time_accel_on_this_thread(nullptr);
        pt_rate.push_back(double(rec.rays.size()) / s.stats().seconds);
        bar.update(double(++done) / total);
        acc_many.push_back(replay_rate(accel, rec, threads, Mode::accel_many, batch));
        bar.update(double(++done) / total);
        acc.push_back(replay_rate(accel, rec, threads, Mode::accel, batch));
        bar.update(double(++done) / total);
        // The replay the path tracer is held against (PT/raw), timed like the path tracer's pass.
        auto replay_timed = [&](Mode m) {
          const bool timing = timed && m == raw_mode;
          if (timing) time_accel_on_this_thread(&raw_timer);
          const uint64_t t0 = accel_ticks();
          const double rate = replay_rate(accel, rec, threads, m, batch);
          if (timing) raw_ticks += accel_ticks() - t0;
          time_accel_on_this_thread(nullptr);
          bar.update(double(++done) / total);
          return rate;
        };
        raw.push_back(replay_timed(Mode::raw));
        stream.push_back(replay_timed(Mode::stream));
        packet.push_back(replay_timed(Mode::packet16));
        packet8.push_back(replay_timed(Mode::packet8));
        if (timed) {  // the minimal loop and the raw replay of its rays, paired as PT/raw is
          time_accel_on_this_thread(&minimal_timer);
          const uint64_t m0 = accel_ticks();
          const MinimalLoopResult loop = minimal_loop_pass(*scene, pixels, p.width, p.height, spp);
          minimal_ticks += accel_ticks() - m0;
          time_accel_on_this_thread(nullptr);
          minimal_rays += loop.rays;
          bar.update(double(++done) / total);
          const double raw_rate = replay_rate(accel, minimal_rec, 1, packet_width == 16 ? Mode::packet16 : Mode::packet8, batch);
          bar.update(double(++done) / total);
          minimal_ratio.push_back((double(loop.rays) / loop.seconds) / raw_rate);
          for (LanesLoop& l : lanes_loops) {
            if (!lanes_loop) break;
            MinimalLoopResult lanes;
            time_accel_on_this_thread(&l.timer);
            const uint64_t l0 = accel_ticks();
            minimal_loop_lanes_pass(*scene, pixels, p.width, p.height, spp, lanes, l.in_place);
            l.ticks += accel_ticks() - l0;
            time_accel_on_this_thread(nullptr);
            l.rays += lanes.rays;
            bar.update(double(++done) / total);
            const double lanes_raw = replay_rate(accel, l.rec, 1, packet_width == 16 ? Mode::packet16 : Mode::packet8, batch);
            bar.update(double(++done) / total);
            l.ratio.push_back((double(lanes.rays) / lanes.seconds) / lanes_raw);
          }
        }
      }
      if (timed) {
        // PT/raw is (Embree's share of PT's time) / (its share of the replay's) when the calls
        // themselves take as long in both: "Embree PT/raw" says how far that holds.
        pt_rest_per_ray = double(pt_ticks - pt_timer.embree - pt_timer.refine) / double(runs) / double(rec.rays.size());
        // The budget: with Embree's share s of the replay and the calls' time in the pass f times
        // theirs there, PT/raw >= 0.70 holds while our own time (refinement and rest) is at most
        // 1 / (0.70 s f) - 1 of the Embree calls' time in the pass.
        const double raw_share = double(raw_timer.embree) / double(raw_ticks);
        const double embree_ratio = double(pt_timer.embree) / double(raw_timer.embree);
        const double own_over_embree = double(pt_ticks - pt_timer.embree) / double(pt_timer.embree);
        const double allowed = 1.0 / (0.70 * raw_share * embree_ratio) - 1.0;
        char line[256];
        std::snprintf(line, sizeof line, "%-10s %9.1f%% %9.1f%% %9.1f%% %11.1f%% %13.2f %9.1f %10.2f %10.2f", sc.name.c_str(),
                      100.0 * pt_timer.embree / pt_ticks, 100.0 * pt_timer.refine / pt_ticks,
                      100.0 * (pt_ticks - pt_timer.embree - pt_timer.refine) / pt_ticks, 100.0 * raw_share,
                      embree_ratio, pt_rest_per_ray, own_over_embree, allowed);
        split.push_back(line);
      }
      // The path tracer casts packets unless told not to; its ceiling is the replay the same way.
      // Each run's PT over the replay right after it, then the median: pairs cancel the machine's
      // slow drift, which a ratio of two medians taken over the whole run does not.
      const std::vector<double>& own = p.ray_packets ? acc_many : acc;
      // Against Embree alone, called the way the path tracer calls it (packets of Accel's width, or
      // single rays): our wrapper's checks and hit refinement count as the path tracer's time there.
      const std::vector<double>& raw_own = !p.ray_packets ? raw : packet_width == 16 ? packet : packet8;
      std::vector<double> paired, paired_raw;
      for (size_t r = 0; r < pt_rate.size(); ++r) {
        paired.push_back(pt_rate[r] / own[r]);
        paired_raw.push_back(pt_rate[r] / raw_own[r]);
      }
      // The spread of the paired ratios: on a noisy host the median alone hides how close it is.
      const auto [lo, hi] = std::minmax_element(paired.begin(), paired.end());
      const auto [raw_lo, raw_hi] = std::minmax_element(paired_raw.begin(), paired_raw.end());
      char line[512];
      std::snprintf(line, sizeof line,
                    "%-10s %7d %8.2f M %7.1f%% %9.2f %9.2f M %10.2f M %10.2f M %10.2f %4.2f-%4.2f %7.2f %4.2f-%4.2f %9.2f M %11.2f M %11.2f M %11.2f M",
                    sc.name.c_str(), threads, rec.rays.size() / 1e6, 100.0 * shadows / std::max<size_t>(1, rec.rays.size()),
                    double(pt_rays) / std::max<uint64_t>(1, pt_samples), median(pt_rate) / 1e6, median(acc) / 1e6,
                    median(acc_many) / 1e6, median(paired), *lo, *hi, median(paired_raw), *raw_lo, *raw_hi, median(raw) / 1e6, median(stream) / 1e6,
                    median(packet) / 1e6, median(packet8) / 1e6);
      table.push_back(line);
      target.add(median(paired_raw), sc.name + ", " + std::to_string(threads) + (threads == 1 ? " thread" : " threads"));
      if (timed) {
        const auto [lo_m, hi_m] = std::minmax_element(minimal_ratio.begin(), minimal_ratio.end());
        const double rest = double(minimal_ticks - minimal_timer.embree - minimal_timer.refine) / double(minimal_rays);
        char row[256];
        std::snprintf(row, sizeof row, "%-10s %8.2f M %7.1f%% %10.2f %4.2f-%4.2f %9.1f %9.1f %11.2f", sc.name.c_str(),
                      minimal_rec.rays.size() / 1e6, 100.0 * minimal_shadows / std::max<size_t>(1, minimal_rec.rays.size()),
                      median(minimal_ratio), *lo_m, *hi_m, rest, pt_rest_per_ray, median(paired_raw) / median(minimal_ratio));
        minimal.push_back(row);
        std::string line = sc.name;
        line.resize(10, ' ');
        for (const LanesLoop& l : lanes_loops) {
          if (!lanes_loop) break;
          const auto [lo_l, hi_l] = std::minmax_element(l.ratio.begin(), l.ratio.end());
          const double lanes_rest = double(l.ticks - l.timer.embree - l.timer.refine) / double(l.rays);
          std::snprintf(row, sizeof row, " %12.2f %4.2f-%4.2f %9.1f %10.4f", median(l.ratio), *lo_l, *hi_l, lanes_rest,
                        l.radiance / std::max(1e-30, minimal_radiance));
          line += row;
        }
        if (lanes_loop) {
          // What PT/raw = 0.70 leaves for the path tracer's features beside the in-place loop: its
          // rays' raw time a ray x (1 / 0.70 - 1 / (in place/raw)); and what they cost today.
          const double raw_per_ray = double(raw_ticks) / double(runs) / double(rec.rays.size());
          std::snprintf(row, sizeof row, " %9.1f %9.1f", raw_per_ray * (1 / 0.70 - 1 / median(lanes_loops[1].ratio)),
                        pt_rest_per_ray - rest);
          lanes_table.push_back(line + row);
        }
      }
    }
  }
  bar.finish();
  std::printf("%-10s %7s %10s %8s %9s %11s %12s %12s %10s %9s %7s %9s %11s %13s %13s %14s\n", "scene", "threads", "rays", "shadow",
              "rays/spl", "PT rays/s", "replay 1", "replay many", "PT/replay", "min-max", "PT/raw", "min-max", "raw 1 rays/s",
              "stream rays/s", "packet16 rays/s", "packet8 rays/s");
  for (const std::string& l : table) std::printf("%s\n", l.c_str());
  std::printf("PT = the path tracer's rays/s on the same pass (rays that reach Accel), %s; replay 1 = Accel::intersect / "
              "occluded; replay many = Accel::intersect_many / occluded_many (packets of %d); PT/replay = median over runs of PT over the "
              "replay that traces as the path tracer does, in the same run (min-max: the smallest and largest of those runs); PT/raw = the same median (and min-max) over Embree called directly the way the path tracer calls it (packets of %d, no checks, no hit refinement); raw 1 = rtcIntersect1 / rtcOccluded1; stream = "
              "rtcIntersect1M / rtcOccluded1M, %zu rays a call; packet16 / packet8 = rtcIntersect16 / rtcOccluded16 and "
              "rtcIntersect8 / rtcOccluded8\n",
              RenderParams().ray_packets ? "in Embree packets" : "one ray at a time", packet_width, packet_width, batch);
  std::printf("%s\n", target.verdict().c_str());
  std::printf("\nWhere the time goes, one thread (AccelTimer, summed over the runs):\n%-10s %10s %10s %10s %12s %13s %9s %10s %10s\n",
              "scene", "PT Embree", "PT refine", "PT rest", "raw Embree", "Embree PT/raw", "rest/ray", "own/Embree", "for 0.70");
  for (const std::string& l : split) std::printf("%s\n", l.c_str());
  std::printf("PT Embree / refine / rest = shares of the path tracer's pass: the Embree calls, Accel's hit refinement "
              "(after packet and single-ray intersections), everything else (sampling, shading, film, our checks around Embree); raw "
              "Embree = Embree's share of the replay PT/raw compares with (the rest packs the packets); Embree PT/raw = "
              "the Embree calls' time in the pass over their time in that replay (1: the same rays cost the same inside "
              "the path tracer); rest/ray = the path tracer's own time a ray, in %s; own/Embree = its refinement and rest "
              "over its Embree calls, for 0.70 = what that may be for PT/raw = 0.70 with the Embree calls costing what they "
              "do in this pass (1 / (0.70 x raw Embree x Embree PT/raw) - 1)\n",
#if defined(__x86_64__) || defined(__i386__)
              "time-stamp-counter ticks");
#else
              "nanoseconds");
#endif
  std::printf("\nA minimal path loop on the same pixels, one thread (bench/minimal_loop.h):\n%-10s %10s %8s %10s %9s %9s %9s %11s\n",
              "scene", "rays", "shadow", "loop/raw", "min-max", "rest/ray", "PT rest", "PT/loop");
  for (const std::string& l : minimal) std::printf("%s\n", l.c_str());
  std::printf("loop/raw = the minimal loop's rays/s over the raw replay of its own rays (packets of %d), median of the runs "
              "(min-max); rest/ray = its own time a ray, PT rest = the path tracer's (above); PT/loop = PT/raw (1 thread) over "
              "loop/raw: how near the path tracer comes to a loop that keeps only its rays\n",
              packet_width);
  if (!lanes_loop) {
    std::printf("\nThe minimal loop in lanes: not run (it needs AVX2)\n");
    return 0;
  }
  std::printf("\nThe same loop with its own work in AVX2 lanes, one thread (bench/minimal_loop_lanes.h):\n%-10s %12s %9s %9s %10s "
              "%12s %9s %9s %10s %9s %9s\n",
              "scene", "records/raw", "min-max", "rest/ray", "light", "in place/raw", "min-max", "rest/ray", "light", "room",
              "features");
  for (const std::string& l : lanes_table) std::printf("%s\n", l.c_str());
  std::printf("records = its rays through Accel::intersect_many / occluded_many (Ray and SurfaceHit records, packed into "
              "packets there); in place = its rays kept in Embree's packet layout (Accel::intersect16 / occluded16, no "
              "packing, hits read in lanes); /raw and rest/ray as above, each against the raw replay of its own rays; light = "
              "what it gathered over the scalar loop's (the same paths with other random numbers: about 1); room = the own "
              "work a ray that PT/raw = 0.70 would leave for the path tracer's features beside the in-place loop (the raw "
              "replay's time a ray of the path tracer's rays x (1/0.70 - 1/(in place/raw))), features = what they cost today "
              "(PT rest less the scalar loop's rest/ray), both in the same ticks\n");
  return 0;
}

int main(int argc, char** argv) { return run_guarded("bench_ceiling", [&] { return bench_main(argc, argv); }); }
