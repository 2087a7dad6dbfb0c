// The debug window's render thread (viewer_loop.h).
#include "viewer_loop.h"

#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <sstream>

#include "film_denoise.h"
#include "scene_file.h"

namespace pt {
namespace viewer {

void say(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  std::vfprintf(stdout, fmt, ap);
  va_end(ap);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

std::string fmt_g(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string scene_base(const std::string& path) {
  for (const char* ext : {".dae", ".gltf", ".glb"}) {
    const size_t n = std::strlen(ext);
    if (path.size() > n && path.compare(path.size() - n, n, ext) == 0) return path.substr(0, path.size() - n);
  }
  return path;
}

std::string output_path(const CliOptions& o, const std::string& suffix) {
  std::string base = scene_base(o.scene_path);
  base = base.substr(base.find_last_of('/') + 1);
  if (o.output_dir.empty()) return base + suffix;
  return o.output_dir + (o.output_dir.back() == '/' ? "" : "/") + base + suffix;
}

void RenderLoop::run() {
  try {
    loop();
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lk(m_sh.mutex);
    m_sh.fatal = e.what();
  }
  m_sh.wake_window();
}

void RenderLoop::loop() {
  std::unique_lock<std::mutex> lk(m_sh.mutex);
  for (;;) {
    if (m_sh.quit) return;
    if (!m_sh.commands.empty()) {
      Command c = m_sh.commands.front();
      m_sh.commands.pop_front();
      RenderParams want = m_sh.want;
      ViewPose view = m_sh.view;
      lk.unlock();
      float focus = handle(c, want, view);
      lk.lock();
      if (c.kind == CommandKind::focus && std::isfinite(focus)) {
        m_sh.want.focal_distance = focus;
        ++m_sh.want_gen;
      }
      ++m_sh.handled;
      m_sh.wake_window();
      continue;
    }
    if (!m_session || m_gen != m_sh.want_gen) {
      RenderParams p = m_sh.want;
      ViewPose view = m_sh.view;
      uint64_t gen = m_sh.want_gen;
      lk.unlock();
      start_session(p, view, gen);
      lk.lock();
      continue;
    }
    if (m_done) {
      m_sh.wake.wait(lk);
      continue;
    }
    // Every request is consumed above with the lock held; one made after this line cancels the pass.
    m_sh.cancel = false;
    lk.unlock();
    uint64_t gen = m_gen;
    RenderSession* s = m_session.get();
    const PassReport r = m_driver->step(&m_sh.cancel, [this, gen, s](const Tile& t) { send_tile(gen, *s, t); });
    // A pass cut short by a cancel is resumed by the next step; one cut short by --time-limit ends
    // the render, as the error target and the sample budget do (the driver decides all three).
    const bool reported = r.completed || m_driver->done();
    if (reported) {
      Status st = m_status;
      if (r.completed) st.reached_spp = r.target_spp;
      st.error = r.error;
      st.finished = m_driver->done();
      st.seconds = r.seconds;
      m_estimate.update(*s, r.seconds, r.error);
      st.progress = m_estimate.progress(r.seconds);
      st.eta = m_estimate.remaining_seconds(r.seconds);
      st.at = Clock::now();
      m_status = st;
      m_done = st.finished;
      const StopReason why = m_driver->reason();
      if (!m_options.quiet)
        say("pass: %d/%d spp, error estimate %s, %.2f s%s", st.reached_spp, st.spp,
            format_error_estimate(st.error).c_str(), st.seconds,
            m_done && why != StopReason::finished ? (std::string(", ") + stop_reason_name(why)).c_str() : "");
      if (r.completed || m_done) denoise_after_pass(r, m_done);
    }
    lk.lock();
    if (reported) m_sh.status = m_status;
    m_sh.wake_window();
  }
}

Camera view_camera(const SceneDesc& desc, const RenderParams& p, const ViewPose& view) {
  Camera c = make_camera(desc, camera_params(p));
  return view.moved ? camera_looking(c, view.position, view.target) : c;
}

std::unique_ptr<RenderScene> RenderLoop::make_scene(const RenderParams& p, const ViewPose& view) {
  auto scene = make_view(m_base, p, m_environment);
  m_environment = scene->environment;
  if (view.moved) scene->camera = view_camera(m_desc, p, view);
  return scene;
}

void RenderLoop::start_session(const RenderParams& p, const ViewPose& view, uint64_t gen) {
  m_driver.reset();
  m_session.reset();
  m_scene = make_scene(p, view);
  m_session = std::make_unique<RenderSession>(*m_scene, p);
  m_driver = std::make_unique<ProgressiveDriver>(*m_session, m_options.limits);
  m_estimate = ProgressEstimate(m_options.limits);
  m_params = p;
  m_gen = gen;
  m_done = false;
  m_denoise_spent = 0;
  m_denoise_failed = false;
  m_status = Status{};
  m_status.gen = gen;
  m_status.width = m_session->width();
  m_status.height = m_session->height();
  m_status.frame_w = p.width;
  m_status.frame_h = p.height;
  m_status.cell_x0 = p.cell_w > 0 ? p.cell_x : 0;
  m_status.cell_y0 = p.cell_w > 0 ? p.height - (p.cell_y + p.cell_h) : 0;
  m_status.spp = p.spp;
  std::lock_guard<std::mutex> lk(m_sh.mutex);
  m_sh.status = m_status;
}

void RenderLoop::denoise_after_pass(const PassReport& r, bool finished) {
  if (!m_session->film().has_features() || m_denoise_failed) return;
  if (!finished && m_denoise_spent > 0.1 * r.seconds) return;  // it would cost more than it shows
  const DenoisedFilm d = denoise_film(m_session->film(), finished ? DenoiseQuality::final : DenoiseQuality::preview,
                                      m_params.threads, false);
  m_denoise_spent += d.seconds;
  if (!d.ok) {
    m_denoise_failed = true;
    say("denoiser: %s; the view stays raw", d.error.c_str());
    return;
  }
  if (!m_options.quiet)
    say("denoised: %d spp in %.3f s (%s)", r.target_spp, d.seconds, finished ? "final" : "preview");
  std::vector<uint8_t> rgb(d.image.pixels.size() * 3);
  for (size_t i = 0; i < d.image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = tonemap_course(d.image.pixels[i][c]);
  std::lock_guard<std::mutex> lk(m_sh.tile_mutex);
  m_sh.denoised.gen = m_gen;
  ++m_sh.denoised.number;
  m_sh.denoised.width = d.image.width, m_sh.denoised.height = d.image.height;
  m_sh.denoised.rgb = std::move(rgb);
}

void RenderLoop::send_tile(uint64_t gen, const RenderSession& s, const Tile& t) {
  TileUpdate u{gen, t, {}, {}, {}};
  std::vector<Vec3> px;
  s.film().read_tile(t, px);
  u.rgb.resize(px.size() * 3);
  for (size_t i = 0; i < px.size(); ++i)
    for (int c = 0; c < 3; ++c) u.rgb[3 * i + c] = tonemap_course(px[i][c]);
  s.film().read_tile_rate(t, px);
  u.rate.resize(px.size() * 3);
  for (size_t i = 0; i < px.size(); ++i)
    for (int c = 0; c < 3; ++c) u.rate[3 * i + c] = tonemap_course(px[i][c]);  // as the _rate.png
  s.film().read_tile_count(t, u.count);
  bool was_empty;
  {
    std::lock_guard<std::mutex> lk(m_sh.tile_mutex);
    was_empty = m_sh.tiles.empty();
    m_sh.tiles.push_back(std::move(u));
  }
  if (was_empty) m_sh.wake_window();
}

float RenderLoop::handle(const Command& c, const RenderParams& want, const ViewPose& view) {
  if (c.kind == CommandKind::focus) {
    // The pinhole ray of the camera the window shows now (pose and size; lens settings do not matter).
    float d = autofocus_distance(*make_scene(want, view), c.sx, c.sy);
    if (std::isfinite(d))
      say("autofocus (%.4f, %.4f): focal distance %s", c.sx, c.sy, fmt_g(d).c_str());
    else
      say("autofocus (%.4f, %.4f): nothing under the cursor, focal distance unchanged", c.sx, c.sy);
    return d;
  }
  if (!m_session) {
    say("save: nothing rendered yet");
    return 0;
  }
  std::time_t now = std::time(nullptr);
  std::tm lt{};
  localtime_r(&now, &lt);
  char stamp[64];
  std::snprintf(stamp, sizeof stamp, "_screenshot_%d-%d_%d-%d-%d", lt.tm_mon + 1, lt.tm_mday, lt.tm_hour, lt.tm_min,
                lt.tm_sec);
  std::string base = output_path(m_options, stamp);
  CliOptions o = m_options;
  o.params = m_params;
  try {
    write_image(m_session->image(), base + ".png");
    write_image(m_session->image(), base + ".exr", render_metadata(o, *m_session));
    write_image(m_session->rate_image(), rate_image_path(base + ".png"));
    say("saved %s.png, %s.exr, %s", base.c_str(), base.c_str(), rate_image_path(base + ".png").c_str());
  } catch (const std::exception& e) {
    say("save failed: %s", e.what());
  }
  return 0;
}

}  // namespace viewer
}  // namespace pt
