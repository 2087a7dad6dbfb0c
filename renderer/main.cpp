// The pathtracer command: course flags -> load scene -> render -> write images -> summary line.
#include <chrono>
#include <cstdio>
#include <sstream>

#include "cli.h"
#include "collada.h"
#include "progress.h"
#include "render.h"

using namespace pt;

namespace {

Metadata render_metadata(const CliOptions& o, const RenderSession& session) {
  const RenderParams& p = o.params;
  SessionStats st = session.stats();
  auto num = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  double pixels = double(session.width()) * session.height();
  return {{"pathtracer:scene", o.scene_path},
          {"pathtracer:spp", std::to_string(p.spp)},
          {"pathtracer:achieved_spp", num(pixels > 0 ? st.samples / pixels : 0)},
          {"pathtracer:light_samples", std::to_string(p.light_samples)},
          {"pathtracer:max_depth", std::to_string(p.max_depth)},
          {"pathtracer:lens_radius", num(p.lens_radius)},
          {"pathtracer:focal_distance", num(p.focal_distance)},
          {"pathtracer:adaptive", p.adaptive ? std::to_string(p.adaptive_batch) + " " + num(p.adaptive_tolerance) : "off"},
          {"pathtracer:direct", p.hemisphere ? "hemisphere" : "light sampling"},
          {"pathtracer:environment", p.env_map},
          {"pathtracer:seed", std::to_string(p.seed)},
          {"pathtracer:threads", std::to_string(p.threads)},
          {"pathtracer:wall_seconds", num(st.seconds)},
          {"pathtracer:error_estimate", num(session.error_estimate())},
          {"pathtracer:nonfinite_samples", std::to_string(st.nonfinite)}};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  CliOptions o;
  try {
    o = parse_cli(args);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "pathtracer: %s\n\n%s", e.what(), usage_text(argv[0]).c_str());
    return 1;
  }
  if (o.help) {
    std::printf("%s", usage_text(argv[0]).c_str());
    return 0;
  }
  if (o.output.empty()) {
    std::fprintf(stderr,
                 "pathtracer: the GLFW debug window is not part of this build yet; give -f FILE to render to a file\n");
    return 2;
  }
  try {
    auto t0 = std::chrono::steady_clock::now();
    SceneDesc desc = load_collada(o.scene_path);
    auto scene = make_render_scene(desc, o.params);
    double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!o.quiet)
      std::fprintf(stderr, "Loaded %s: %zu triangles, %zu spheres, %zu lights in %.3f s\n", o.scene_path.c_str(),
                   scene->triangle_count, scene->sphere_count, scene->lights.size(), load_s);

    RenderSession session(*scene, o.params);
    ProgressBar bar("Rendering", !o.quiet);
    session.render_all(nullptr, [&] { bar.update(session.progress()); });
    bar.finish();

    Metadata meta = render_metadata(o, session);
    write_image(session.image(), o.output, meta);
    write_image(session.rate_image(), rate_image_path(o.output));

    SessionStats st = session.stats();
    double pixels = double(session.width()) * session.height();
    std::printf("%s: %dx%d, %.1f spp avg (max %d), %.2f s, %.3g samples/s, %.3g rays/s, error estimate %.3g%s\n",
                o.output.c_str(), session.width(), session.height(), st.samples / pixels, o.params.spp, st.seconds,
                st.samples / st.seconds, st.rays / st.seconds, session.error_estimate(),
                st.nonfinite ? (", " + std::to_string(st.nonfinite) + " non-finite samples dropped").c_str() : "");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pathtracer: %s\n", e.what());
    return 1;
  }
}
