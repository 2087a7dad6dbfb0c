// What signing costs a render farm (docs/performance.md, "Signed farm passes"): per frame size,
// the worker's HMAC-SHA256 of a pass result (server/farm_security.h, over the pass's wire bytes)
// and the server's check of it, against the time a worker spends rendering a pass of cornell.dae
// (the 1-spp passes a job starts with) and against the pass time the server's plan grows passes to
// (PassPlan in server/redis_backend.cpp: 2 s, or what sends 4 MB/s for large frames).
// Medians of several runs; threads as a worker would use them.
//
//   ./build/bench_farm_sign [--runs N] [--threads T]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "args.h"
#include "bench_common.h"
#include "farm_security.h"
#include "redis_queue.h"
#include "render_scene.h"
#include "scene_file.h"
#include "session.h"

namespace {

using clock_type = std::chrono::steady_clock;

using bench::median;
double since(clock_type::time_point t0) { return bench::seconds_since(t0); }

}  // namespace

int main(int argc, char** argv) {
  bench::Args args(argc, argv, "bench_farm_sign [--runs N=9] [--threads T=2]");
  if (args.help()) return 0;
  const int runs = args.integer("--runs", 9, 1, 1000);
  const int threads = args.integer("--threads", 2, 1, 1024);
  args.finish();
  bench::print_host("bench_farm_sign");
  const pt::SceneBase base = pt::make_scene_base(pt::load_scene(PT_SOURCE_DIR "/scenes/cornell.dae"));
  const srv::FarmKey key("bench-farm-key-0123456789abcdef");
  struct Size { int w, h; };
  std::printf("frame       MB/pass  sign ms  check ms  1-spp pass ms  planned pass s  sign / 1-spp pass  sign / planned  check / planned\n");
  for (Size s : {Size{240, 180}, Size{480, 360}, Size{800, 600}, Size{1920, 1080}}) {
    pt::RenderParams params;
    params.width = s.w, params.height = s.h, params.spp = 1024, params.threads = threads, params.adaptive = false;
    auto scene = pt::make_view(base, params);
    std::vector<double> render, sign, check;
    std::string wire;
    for (int k = 0; k < runs; ++k) {
      auto t0 = clock_type::now();
      pt::FilmPass pass = pt::render_film_pass(*scene, params, uint32_t(k), 1, {}, nullptr);
      render.push_back(since(t0));
      wire = pass.encode();
      t0 = clock_type::now();
      const std::string sig = srv::rq::result_signature(key, "1a2b3c4d5e6f7a8b", "0123456789abcdef", std::to_string(k),
                                                        "worker-1", "1", wire, "albedo,normal");
      sign.push_back(since(t0));
      t0 = clock_type::now();
      const bool ok = key.verify(sig, {"pt-result", "1a2b3c4d5e6f7a8b", "0123456789abcdef", std::to_string(k),
                                       "worker-1", "1", wire, "albedo,normal"});
      check.push_back(since(t0));
      if (!ok) return 1;
    }
    const double r = median(render), sg = median(sign), ch = median(check);
    const double planned = std::max(2.0, double(wire.size()) / 4e6);  // kPassSeconds, kPassBytesPerSecond
    std::printf("%4dx%-4d  %8.2f  %7.2f  %8.2f  %13.1f  %14.1f  %16.1f%%  %13.2f%%  %14.2f%%\n", s.w, s.h,
                wire.size() / 1e6, 1e3 * sg, 1e3 * ch, 1e3 * r, planned, 100 * sg / r, 100 * sg / planned,
                100 * ch / planned);
  }
  return 0;
}
