// The pathtracer command's body: course flags -> load scene -> render -> write images -> summary
// line; without -f, the debug window (viewer.cpp). Its mains: renderer/cmd/pathtracer.cpp, and the
// test build's with the window's script player (tests/pathtracer_scripted.cpp).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <new>
#include <string>

#include "cli.h"
#include "film_denoise.h"
#include "scene_file.h"
#include "hints.h"
#include "progress.h"
#include "render_job.h"
#include "session.h"
#include "version.h"
#include "viewer.h"

using namespace pt;

namespace {

// --describe: what the scene uses (and so which specialised path loop runs) and what it costs.
int describe_scene(const CliOptions& o, const SceneDesc& desc, const RenderScene& scene, double load_s) {
  const SceneFeatures& f = scene.features;
  auto join = [](const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
    return s.empty() ? std::string("none") : s;
  };
  size_t bytes = scene.accel->memory_bytes();
  size_t prims = desc.triangle_count() + desc.spheres.size();
  std::printf("scene:            %s\n", o.scene_path.c_str());
  std::printf("geometry:         %zu triangles in %zu meshes, %zu spheres\n", desc.triangle_count(), desc.meshes.size(),
              desc.spheres.size());
  std::printf("materials:        %s\n", join(f.materials).c_str());
  std::printf("lights:           %s (%zu)\n", join(f.lights).c_str(), scene.lights.size());
  std::printf("environment map:  %s\n", f.environment ? o.params.env_map.c_str() : "no");
  std::printf("shading normals:  %s\n", f.shading_normals ? "yes (curved meshes)" : "no (flat shading)");
  std::printf("camera:           %s\n", f.thin_lens ? "thin lens" : "pinhole");
  std::printf("adaptive:         %s\n", f.adaptive ? "on" : "off (spp <= batch, or --no-adaptive)");
  // The course's defaults (-s 1 -m 1) leave caustics path traced in scenes that light trace them
  // at any real setting: say so, rather than let "path traced only" read as the scene's nature.
  std::string caustics = f.caustic_tracing ? "light traced" : "path traced only";
  RenderParams deeper = o.params;
  deeper.spp = std::max(deeper.spp, 2);
  deeper.max_depth = std::max(deeper.max_depth, 2);
  if (!f.caustic_tracing && caustic_tracing_applies(scene, deeper))
    caustics += " (-s 2 -m 2 or more would light-trace them)";
  std::printf("caustics:         %s\n", caustics.c_str());
  std::printf("textures:         %s\n", !f.textured ? "no"
                                      : f.textures ? (std::to_string(f.textures) + " (and vertex colours where meshes have them)").c_str()
                                                   : "vertex colours");
  std::printf("path loop:        %s%s%s%s\n", f.bits == kFeatAll ? (f.textured ? "generic (textures)" : "generic") : "specialised:",
              f.bits == kFeatAll ? "" : ((f.bits & kFeatDelta) ? " delta" : " no-delta"),
              f.bits == kFeatAll ? "" : ((f.bits & kFeatMicrofacet) ? " microfacet" : " no-microfacet"),
              f.bits == kFeatAll ? "" : ((f.bits & kFeatInfinite) ? " infinite-lights" : " no-infinite-lights"));
  if (packets_apply(o.params)) std::printf("ray queries:      paths in Embree packets of %d\n", scene.accel->packet_width());
  else std::printf("ray queries:      one path at a time\n");
  std::printf("render memory:    %.2f MiB (%.1f bytes per primitive: BVH, vertices, indices, shading data)\n",
              bytes / 1048576.0, prims ? double(bytes) / prims : 0.0);
  std::printf("load + build:     %.3f s\n", load_s);
  return 0;
}

}  // namespace

int pt::pathtracer_main(const std::vector<std::string>& args, const char* argv0, viewer::WindowScript* script) {
  CliOptions o;
  try {
    o = parse_cli(args);
  } catch (const UsageError& e) {  // one line, not the whole help
    std::fprintf(stderr, "pathtracer: %s (see --help)\n", e.what());
    return 1;
  }
  if (o.help) {
    std::printf("%s", usage_text(argv0).c_str());
    return 0;
  }
  if (o.version) {
    std::printf("%s\n", version_text("pathtracer").c_str());
    return 0;
  }
  if (o.denoise && !o.describe && !Denoiser::shared().available()) {  // before the render, not after it
    std::fprintf(stderr, "pathtracer: --denoise: %s\n", Denoiser::shared().description().c_str());
    return 1;
  }
  if (o.output.empty() && !o.describe) return run_viewer(o, script);
  if (script) {
    std::fprintf(stderr, "pathtracer: --script drives the window; it cannot be used with -f\n");
    return 1;
  }
  std::string doing = "loading " + o.scene_path;  // what an out-of-memory message names
  try {
    if (!o.describe) check_image_output(o.output);  // before the render, not after it
    auto t0 = std::chrono::steady_clock::now();
    SceneDesc desc = load_scene(o.scene_path);
    auto scene = make_render_scene(desc, o.params);
    double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (o.describe) return describe_scene(o, desc, *scene, load_s);
    if (!o.quiet) {
      const bool course_framing = o.params.camera_file.empty() && !o.params.file_camera &&
                                  !(desc.camera.as_authored && desc.camera.present);
      for (const std::string& h : render_hints(o, scene->features, scene->camera, desc.geometry_bounds(), course_framing))
        std::fprintf(stderr, "hint: %s\n", h.c_str());
    }
    const std::vector<std::string> input_files = desc.input_files;  // for the checkpoint's fingerprint
    desc = SceneDesc();  // the render scene holds what rendering reads: drop the file's copy
    if (!o.quiet)
      std::fprintf(stderr, "Loaded %s: %s in %.3f s\n", o.scene_path.c_str(), loaded_counts(*scene).c_str(), load_s);

    doing = "for a " + std::to_string(o.params.width) + "x" + std::to_string(o.params.height) +
            " render (its per-pixel statistics and images); a smaller -r needs less";
    RenderSession session(*scene, o.params);
    ImageRGB reference;
    if (!o.reference.empty()) {
      reference = read_image(o.reference);
      if (reference.width != session.width() || reference.height != session.height())
        throw std::runtime_error(o.reference + ": the reference is " + std::to_string(reference.width) + "x" +
                                 std::to_string(reference.height) + ", the render " + std::to_string(session.width()) +
                                 "x" + std::to_string(session.height()));
    }
    FILE* log = nullptr;
    if (!o.error_log.empty()) {
      log = std::fopen(o.error_log.c_str(), "w");
      if (!log) throw std::runtime_error(o.error_log + ": cannot write the error log");
      std::fprintf(log, "seconds,spp,error_estimate%s%s\n", reference.pixels.empty() ? "" : ",rmse,rel_mse",
                   !o.denoise                 ? ""
                   : reference.pixels.empty() ? ",denoise_seconds,preview_denoise_seconds"
                                              : ",denoise_seconds,denoised_rel_mse,preview_denoise_seconds,"
                                                "preview_rel_mse");
    }
    ProgressBar bar("Rendering", !o.quiet);
    double pixels = double(session.width()) * session.height();
    std::unique_ptr<Checkpointer> checkpoints;
    if (!o.checkpoint.empty()) {
      std::ifstream scene_file(o.scene_path, std::ios::binary);
      checkpoints = std::make_unique<Checkpointer>(
          o.checkpoint, render_fingerprint(std::string(std::istreambuf_iterator<char>(scene_file), {}), o.params, input_files),
          o.checkpoint_interval);
    }
    // The bar, its log and the ETA follow the render's ProgressEstimate (driver.h), on a clock of
    // rendering time that goes on from a checkpoint's, as the time limit does.
    double resumed = 0;
    auto render_start = std::chrono::steady_clock::now();
    auto clock = [&] { return resumed + std::chrono::duration<double>(std::chrono::steady_clock::now() - render_start).count(); };
    ProgressEstimate estimate(o.limits);
    std::atomic<double> last_error{INFINITY};
    FILE* progress_log = nullptr;
    if (!o.progress_log.empty()) {
      progress_log = std::fopen(o.progress_log.c_str(), "w");
      if (!progress_log) throw std::runtime_error(o.progress_log + ": cannot write the progress log");
      std::fprintf(progress_log, "seconds,progress,eta,budget_progress,pass_end,samples,samples_left\n");
    }
    std::mutex log_mutex;
    double logged_at = -1;
    auto log_progress = [&](double t, double fraction, double eta, bool pass_end) {
      std::lock_guard<std::mutex> lock(log_mutex);
      if (!pass_end && t < logged_at + 0.1) return;  // tiles: 10 rows a second at most
      logged_at = t;
      const Film::Work& work = estimate.work();  // as of the last pass's end
      std::fprintf(progress_log, "%.4f,%.6f,%.4f,%.6f,%d,%llu,%llu\n", t, fraction, eta, session.progress(),
                   int(pass_end), (unsigned long long)work.taken, (unsigned long long)work.left);
      if (pass_end) std::fflush(progress_log);
    };
    RenderJobEvents events;
    events.started = [&](bool restored) {
      resumed = session.seconds();
      render_start = std::chrono::steady_clock::now();
      if (restored && !o.quiet)
        std::fprintf(stderr, "Resuming from %s: %.1f spp a pixel, %.2f s rendered\n", o.checkpoint.c_str(),
                     session.stats().samples / pixels, session.seconds());
    };
    events.tile = [&](const Tile&) {
      const double t = clock(), eta = estimate.remaining_seconds(t);
      const double fraction = estimate.progress(t);
      if (progress_log) log_progress(t, fraction, eta, false);
      // Below 1 until done: the bar redraws at once for 1, which would be every tile.
      const double err = last_error.load();
      bar.update(std::min(0.999, fraction), std::isfinite(err) ? "error " + format_error_estimate(err) : std::string(), eta);
    };
    events.pass = [&](const PassReport& r) {
      const double t = clock();
      estimate.update(session, t, r.error);
      last_error = r.error;
      if (progress_log) log_progress(t, estimate.progress(t), estimate.remaining_seconds(t), true);
      if (!log) return;
      std::fprintf(log, "%.6f,%.4f,%.6g", r.seconds, session.stats().samples / pixels, r.error);
      if (!reference.pixels.empty()) {
        ImageRGB img = session.image();
        std::fprintf(log, ",%.6g,%.6g", rmse(img, reference), relative_mse(img, reference));
      }
      if (o.denoise) {  // the image --denoise would write after this pass, and what it took
        const DenoisedFilm d = denoise_film(session.film(), DenoiseQuality::final, o.params.threads, false);
        std::fprintf(log, ",%.6g", d.seconds);
        if (!reference.pixels.empty()) std::fprintf(log, ",%.6g", d.ok ? relative_mse(d.image, reference) : NAN);
        // And what the window's and the page's pictures at pass ends cost (fast quality).
        const DenoisedFilm p = denoise_film(session.film(), DenoiseQuality::preview, o.params.threads, false);
        std::fprintf(log, ",%.6g", p.seconds);
        if (!reference.pixels.empty()) std::fprintf(log, ",%.6g", p.ok ? relative_mse(p.image, reference) : NAN);
      }
      std::fprintf(log, "\n");
      std::fflush(log);
    };
    const StopReason why = run_render_job(session, o.limits, checkpoints.get(), nullptr, events);
    bar.finish();
    if (log) std::fclose(log);
    if (progress_log) std::fclose(progress_log);

    Metadata meta = render_metadata(o, session);
    meta.push_back({"pathtracer:stopped", stop_reason_name(why)});
    DenoisedFilm denoised;
    if (o.denoise) {
      denoised = denoise_film(session.film(), DenoiseQuality::final, o.params.threads, true);
      if (!denoised.ok)  // the raw render is still worth its file
        std::fprintf(stderr, "pathtracer: warning: %s; writing the raw image\n", denoised.error.c_str());
    }
    if (denoised.ok) {
      const ImageRGB raw = session.image();
      const FilmFeatures features = session.film().features();
      meta.push_back({"pathtracer:denoised", std::string("final, ") + Denoiser::shared().description()});
      meta.push_back({"pathtracer:denoised_noise_estimate", format_error_estimate(denoised.noise)});
      write_image(denoised.image, o.output, meta,
                  {{"raw", &raw}, {"albedo", &features.albedo}, {"normal", &features.normal, true}});
    } else {
      write_image(session.image(), o.output, meta);
    }
    write_image(session.rate_image(), rate_image_path(o.output));

    SessionStats st = session.stats();
    // The estimate compares two halves of each pixel's samples: with one sample a pixel there is none.
    const double err = session.error_estimate();
    const std::string err_text = format_error_estimate(err) + (std::isfinite(err) ? "" : " (needs 2 or more spp)");
    if (checkpoints && checkpoints->saves() > 0)
      std::printf("%s: %d checkpoint%s written in %.3f s\n", o.checkpoint.c_str(), checkpoints->saves(),
                  checkpoints->saves() == 1 ? "" : "s", checkpoints->save_seconds());
    // The estimate is the raw render's; the denoised image's is the spread of its denoised halves.
    char denoise_text[160] = "";
    if (denoised.ok)
      std::snprintf(denoise_text, sizeof denoise_text,
                    ", denoised in %.3f s (noise estimate %s from its denoised halves, bias not included)",
                    denoised.seconds, format_error_estimate(denoised.noise).c_str());
    std::printf("%s: %dx%d, %.1f spp avg (max %d), %.2f s, %.3g samples/s, %.3g rays/s, error estimate %s%s%s%s\n",
                o.output.c_str(), session.width(), session.height(), st.samples / pixels, o.params.spp, st.seconds,
                st.samples / st.seconds, st.rays / st.seconds, (err_text + (o.denoise ? " (raw)" : "")).c_str(),
                denoise_text,
                why == StopReason::finished ? "" : (std::string(", ") + stop_reason_name(why)).c_str(),
                st.nonfinite ? (", " + std::to_string(st.nonfinite) + " non-finite samples dropped").c_str() : "");
    return 0;
  } catch (const std::bad_alloc&) {  // its what() says only "std::bad_alloc"
    std::fprintf(stderr, "pathtracer: out of memory %s\n", doing.c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pathtracer: %s\n", e.what());
    return 1;
  }
}
