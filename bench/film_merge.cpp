// The render server's cost per pass with --queue redis (docs/scale-out.md), without Redis or a
// renderer: decode a pt::FilmPass from its wire bytes, merge it, and read the merged frame back as
// tiles (what the server publishes after every merge). The passes hold synthetic radiance sums of 8
// samples a pixel; the work is the same for any content. Median of several passes per frame size.
//
//   ./build/bench_film_merge [--passes N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "args.h"
#include "bench_common.h"
#include "session.h"

namespace {

using clock_type = std::chrono::steady_clock;

using bench::median;
double since(clock_type::time_point t0) { return bench::seconds_since(t0); }

pt::FilmPass synthetic_pass(int w, int h, uint32_t first, uint32_t count, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.f, 1.f);
  pt::FilmPass p;
  p.width = w;
  p.height = h;
  p.first = first;
  p.count = count;
  size_t n = size_t(w) * h;
  p.sum.resize(n);
  p.lum2.resize(n);
  p.samples.assign(n, count);
  for (size_t i = 0; i < n; ++i) {
    float v = u(rng) * count;
    p.sum[i] = {v, 0.9f * v, 0.8f * v};
    p.lum2[i] = v * v / count;
  }
  p.rays = n * count * 3;
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  bench::Args args(argc, argv, "bench_film_merge [--passes N=9]");
  const int passes = args.integer("--passes", 9, 1, 1000);
  args.finish();
  bench::print_host("bench_film_merge");
  struct Size { int w, h; };
  std::printf("frame        MB/pass  encode ms  decode ms  merge ms  tiles ms  server ms/pass (decode+merge+tiles)\n");
  for (Size s : {Size{240, 180}, Size{480, 360}, Size{800, 600}, Size{1920, 1080}}) {
    pt::RenderParams params;
    params.width = s.w;
    params.height = s.h;
    params.spp = 8 * (passes + 1);
    params.adaptive = false;
    std::vector<pt::Tile> tiles;
    for (int y = 0; y < s.h; y += params.tile_size)
      for (int x = 0; x < s.w; x += params.tile_size)
        tiles.push_back({x, y, std::min(x + params.tile_size, s.w), std::min(y + params.tile_size, s.h)});
    pt::Film film(s.w, s.h, params.spp, pt::adaptive_rule(params), false);
    std::mt19937 rng(1);
    std::vector<double> enc, dec, mer, til;
    size_t bytes = 0;
    std::vector<pt::Vec3> buf;
    for (int k = 0; k < passes; ++k) {
      pt::FilmPass pass = synthetic_pass(s.w, s.h, uint32_t(8 * k), 8, rng);
      auto t0 = clock_type::now();
      std::string wire = pass.encode();
      enc.push_back(since(t0));
      bytes = wire.size();
      t0 = clock_type::now();
      pt::FilmPass back = pt::FilmPass::decode(wire, s.w, s.h);
      dec.push_back(since(t0));
      t0 = clock_type::now();
      film.merge(back);
      mer.push_back(since(t0));
      t0 = clock_type::now();
      for (const pt::Tile& t : tiles) film.read_tile(t, buf);
      til.push_back(since(t0));
    }
    double d = median(dec), m = median(mer), t = median(til);
    std::printf("%4dx%-4d  %9.2f  %9.2f  %9.2f  %8.2f  %8.2f  %8.2f\n", s.w, s.h, bytes / 1e6, 1e3 * median(enc),
                1e3 * d, 1e3 * m, 1e3 * t, 1e3 * (d + m + t));
  }
  return 0;
}
