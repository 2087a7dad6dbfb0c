// The pathtracer command: course flags -> load scene -> render -> write images -> summary line;
// without -f, the debug window (viewer.cpp).
#include <chrono>
#include <cstdio>

#include "cli.h"
#include "collada.h"
#include "progress.h"
#include "render.h"
#include "viewer.h"

using namespace pt;

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
  if (o.output.empty()) return run_viewer(o);
  if (!o.script.empty()) {
    std::fprintf(stderr, "pathtracer: --script drives the window; it cannot be used with -f\n");
    return 1;
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
