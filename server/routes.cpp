// HTTP routes: one table of (method, path, handler), grouped by resource, from which both the
// registration with httplib and the Allow header of a 405 are made. Handlers are thin: they
// validate, call the job service, or copy a status snapshot. What every request passes first is
// http_guard.cpp; the event stream and the shared image encodings, event_stream.cpp.
#include "routes.h"

#include <cmath>
#include <cstring>
#include <functional>
#include <regex>

#include "denoiser.h"
#include "event_stream.h"
#include "image.h"
#include "job_store.h"
#include "scene_file.h"
#include "version.h"

namespace srv {

namespace {

using Request = httplib::Request;
using Response = httplib::Response;
using Handler = void (*)(JobManager&, const ApiOptions&, const Request&, Response&);

std::shared_ptr<Job> job_or_404(JobManager& jobs, const Request& req) {
  auto job = jobs.get(req.matches[1]);  // ids are hex digits, so an odd one is no job
  if (!job) throw JobError(JobErrorKind::not_found, "no job '" + std::string(req.matches[1]) + "'");
  return job;
}

// ---- the service ----

void get_health(JobManager& jobs, const ApiOptions& options, const Request& req, Response& res) {
  size_t queued = 0, running = 0, paused = 0;
  for (auto& j : jobs.list()) {
    std::lock_guard<std::mutex> lock(j->mutex);
    queued += j->state == JobState::queued;
    running += j->state == JobState::running;
    paused += j->state == JobState::paused;
  }
  json health{{"status", "ok"}, {"queued", queued}, {"running", running}, {"paused", paused}, {"rendering", jobs.backend_name()},
              {"data_bytes", jobs.data_bytes()}};
  const pt::VersionInfo& v = pt::version_info();
  health["version"] = {{"version", v.version}, {"commit", v.commit}, {"embree", v.embree}, {"openimageio", v.openimageio}};
  StreamStats st = stream_stats();
  health["stream"] = {{"watchers", st.watchers}, {"png_encodes", st.png_encodes}, {"tile_events", st.tile_events}};
  int workers = jobs.live_workers();
  if (workers >= 0) health["workers"] = workers;  // also refreshes the farm's live workers
  if (json farm = jobs.farm(); !farm.is_null()) {
    // The probe answers without the token; who works for the farm, on which Redis, is for those with it.
    if (!authorized(req, options.token))
      for (const char* k : {"queue", "workers", "rejections"}) farm.erase(k);
    health["farm"] = std::move(farm);
  }
  const pt::Denoiser& denoiser = pt::Denoiser::shared();  // a job's denoise field needs it
  health["denoiser"] = {{"available", denoiser.available()}, {"description", denoiser.summary()}};
  send_json(res, 200, health);
}

void get_openapi(JobManager&, const ApiOptions& options, const Request&, Response& res) {
  res.set_content(options.openapi, "application/json");
}

// ---- scenes ----

void list_scenes(JobManager& jobs, const ApiOptions&, const Request&, Response& res) {
  send_json(res, 200, {{"scenes", jobs.scenes().list()}, {"defaults", job_spec_defaults()}});
}

// PUT /api/scenes/{name}: the raw scene file, loaded before it is stored (201 new, 200 replaced;
// 422 with the loader's message). The body's media type is the scene's own: a browser cannot send
// those cross-site without asking first.
void put_scene(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  const std::string type = media_type(req.get_header_value("Content-Type"));
  if (!is_scene_media_type(type))  // http_guard refused it already; kept beside the route it guards
    throw HttpError(415, std::string("Content-Type must be the scene's own: ") + kSceneMediaTypes);
  const std::string name = req.matches[1];
  try {
    auto [summary, created] = jobs.store_scene(name, req.body);
    std::fprintf(stderr, "render-server: scene '%s' uploaded (%zu bytes)\n", name.c_str(), req.body.size());
    send_json(res, created ? 201 : 200, {{"name", name}, {"source", "uploaded"}, {"summary", summary}});
  } catch (const pt::SceneError& e) {
    throw JobError(JobErrorKind::scene_broken, to_valid_utf8(e.what()), "body");
  }
}

void get_scene(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  send_json(res, 200, jobs.scenes().entry(req.matches[1]));
}

void delete_scene(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  const std::string name = req.matches[1];
  jobs.delete_scene(name);
  send_json(res, 200, {{"name", name}, {"state", "deleted"}});
}

// ---- jobs ----

void check_job(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  JobSpec spec = jobs.check(parse_body(req));
  send_json(res, 200, {{"valid", true}, {"spec", job_spec_to_json(spec)},
                       {"view", view_json(jobs.scenes().view(spec.scene, spec.params))}});
}

void submit_job(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  std::string key = req.get_header_value("Idempotency-Key");
  if (key.size() > 200) throw HttpError(400, "Idempotency-Key is longer than 200 characters", "Idempotency-Key");
  if (!valid_utf8(key)) throw HttpError(400, "Idempotency-Key is not valid UTF-8", "Idempotency-Key");
  auto [job, created] = jobs.submit(parse_body(req), key);
  std::lock_guard<std::mutex> lock(job->mutex);
  res.set_header("Location", "/api/jobs/" + job->id);
  send_json(res, created ? 201 : 200, jobs.status_json(*job));
}

// Newest first, a page at a time: ?limit=N (1-1000, default 100), ?cursor= the next_cursor of the
// page before, ?state= one state only.
void list_jobs(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  size_t limit = 100;
  if (req.has_param("limit")) {
    const std::string v = req.get_param_value("limit");
    char* end = nullptr;
    const long n = std::strtol(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0' || n < 1 || n > 1000)
      throw HttpError(400, "query parameter 'limit' must be a whole number from 1 to 1000", "limit");
    limit = size_t(n);
  }
  const std::string cursor = req.has_param("cursor") ? req.get_param_value("cursor") : "";
  if (cursor.size() > 40 || cursor.find_first_not_of("0123456789abcdef") != std::string::npos)
    throw HttpError(400, "query parameter 'cursor' must be a next_cursor this list gave", "cursor");
  JobPage page = jobs.page(limit, cursor, req.has_param("state") ? req.get_param_value("state") : "");
  json list = json::array();
  for (auto& j : page.jobs) {
    std::lock_guard<std::mutex> lock(j->mutex);
    list.push_back(jobs.status_json(*j, false));
  }
  send_json(res, 200, {{"jobs", list}, {"next_cursor", page.next_cursor.empty() ? json(nullptr) : json(page.next_cursor)}});
}

void get_job(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  auto job = job_or_404(jobs, req);
  std::lock_guard<std::mutex> lock(job->mutex);
  send_json(res, 200, jobs.status_json(*job));
}

// On a finished job: deletes it and its files. On a live one: cancels it (the answer's state is
// the state after the request).
void delete_job(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  const std::string id = req.matches[1];
  if (jobs.remove(id)) return send_json(res, 200, {{"id", id}, {"state", "deleted"}});
  auto job = job_or_404(jobs, req);
  std::lock_guard<std::mutex> lock(job->mutex);
  send_json(res, 200, jobs.status_json(*job));
}

// POST /api/jobs/{id}/pause, /resume and /continue: the job's status after the request.
void control_job(JobManager& jobs, const Request& req, Response& res, const std::function<void(const std::string&)>& act) {
  auto job = job_or_404(jobs, req);
  act(job->id);
  std::lock_guard<std::mutex> lock(job->mutex);
  send_json(res, 200, jobs.status_json(*job));
}

void pause_job(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  control_job(jobs, req, res, [&](const std::string& id) { jobs.pause(id); });
}

void resume_job(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  control_job(jobs, req, res, [&](const std::string& id) { jobs.resume(id); });
}

void continue_job(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  const json body = req.body.empty() ? json::object() : parse_body(req);
  control_job(jobs, req, res, [&](const std::string& id) { jobs.continue_job(id, body); });
}

// ---- a job's image ----

void get_image(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  auto job = job_or_404(jobs, req);
  std::string ext = req.matches[2];
  const char* type = ext == "png" ? "image/png" : "image/x-exr";
  // ?raw=1: a denoised job's raw render (any other job's image is raw already).
  const std::string raw_param = req.has_param("raw") ? req.get_param_value("raw") : "0";
  if (raw_param != "0" && raw_param != "1") throw HttpError(400, "raw must be 0 or 1", "raw");
  const bool raw = raw_param == "1";
  bool done, has_image, denoised;
  std::string state;
  {
    std::lock_guard<std::mutex> lock(job->mutex);
    done = job->state == JobState::done;
    has_image = job->has_image;
    denoised = !raw && !job->denoised.linear.empty();
    state = job_state_name(job->state);
  }
  if (!done && !has_image) throw HttpError(404, "job has no image yet (state " + state + ")");
  res.set_header("Cache-Control", "no-store");
  std::string data;
  // A done job's files (a regular file only: never a link or a FIFO someone put there); a denoised
  // job keeps its raw render beside them.
  const std::string dir = jobs.job_dir(job->id) + "/";
  if (done && raw && read_file(dir + "image_raw." + ext, data)) return res.set_content(data, type);
  if (done && read_file(dir + "image." + ext, data)) return res.set_content(data, type);
  if (!has_image) throw HttpError(404, "the job's image is missing");
  if (ext == "png" && !denoised) return res.set_content(current_png(*job), type);  // encoded once a pass for all
  pt::ImageRGB img;
  std::vector<uint8_t> display;
  {
    std::lock_guard<std::mutex> lock(job->mutex);
    img.width = job->width;
    img.height = job->height;
    img.pixels.resize(size_t(img.width) * img.height);
    const std::vector<float>& linear = denoised ? job->denoised.linear : job->linear;
    if (linear.size() != img.pixels.size() * 3) throw HttpError(404, "the job's image is missing");
    if (ext == "png") display = job->denoised.display;
    else std::memcpy(static_cast<void*>(img.pixels.data()), linear.data(), img.pixels.size() * sizeof(pt::Vec3));
  }
  // Outside the mutex the render threads take.
  if (ext == "png") return res.set_content(pt::encode_png8(display, img.width, img.height), type);
  res.set_content(pt::encode_exr(img), type);
}

// GET /api/jobs/{id}/pixels: the linear image as little-endian float32, (R, G, B, samples taken) a
// pixel, rows top to bottom; its size in X-Image-Width / X-Image-Height. The page's viewer tools
// (exposure, display mappings, the pixel readout, the sample-rate view) work on these exact values.
void get_pixels(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  auto job = job_or_404(jobs, req);
  int w = 0, h = 0;
  std::vector<float> rgb;
  std::vector<uint32_t> counts;
  bool done;
  std::string state;
  {
    std::lock_guard<std::mutex> lock(job->mutex);
    done = job->state == JobState::done;
    state = job_state_name(job->state);
    if (job->has_image) {
      w = job->width, h = job->height;
      rgb = job->linear;
      counts = job->counts;
    }
  }
  if (w == 0) {
    if (!done) throw HttpError(404, "job has no image yet (state " + state + ")");
    // Finished before a restart: its files hold what the memory held (a denoised job's raw render
    // is image_raw.exr: these are the samples' values).
    const std::string dir = jobs.job_dir(job->id);
    const std::string file = dir + (is_regular_file(dir + "/image_raw.exr") ? "/image_raw.exr" : "/image.exr");
    std::string bytes;
    if (!is_regular_file(file)) throw HttpError(404, "the job's image is missing");
    if (!read_file(dir + "/samples.bin", bytes)) throw HttpError(404, "the job's sample counts are missing");
    const pt::ImageRGB img = pt::read_image(file);
    if (!decode_sample_counts(bytes, img.pixels.size(), counts))
      throw HttpError(404, "the job's sample counts do not fit its image");
    w = img.width, h = img.height;
    rgb.resize(img.pixels.size() * 3);
    std::memcpy(rgb.data(), static_cast<const void*>(img.pixels.data()), rgb.size() * sizeof(float));
  }
  const size_t n = size_t(w) * h;
  if (rgb.size() != 3 * n || counts.size() != n)  // never expected: a job's arrays are sized together
    throw HttpError(404, "the job's pixels and sample counts do not match its size");
  std::string body(n * 16, '\0');
  auto put = [&body](size_t at, float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    for (int b = 0; b < 4; ++b) body[at + b] = char((bits >> (8 * b)) & 0xff);
  };
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) put(16 * i + 4 * c, rgb[3 * i + c]);
    put(16 * i + 12, float(counts[i]));
  }
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Image-Width", std::to_string(w));
  res.set_header("X-Image-Height", std::to_string(h));
  res.set_content(body, "application/octet-stream");
}

void get_focus(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  auto job = job_or_404(jobs, req);
  auto coord = [&](const char* name) {
    if (!req.has_param(name)) throw HttpError(400, std::string("query parameter '") + name + "' is required", name);
    std::string v = req.get_param_value(name);
    char* end = nullptr;
    double d = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(d))
      throw HttpError(400, std::string("query parameter '") + name + "' must be a number", name);
    return d;
  };
  double x = coord("x"), y = coord("y");
  double d = jobs.focus_distance(*job, x, y);
  send_json(res, 200, {{"x", x}, {"y", y}, {"distance", std::isfinite(d) ? json(d) : json(nullptr)}});
}

void watch_job(JobManager& jobs, const ApiOptions&, const Request& req, Response& res) {
  auto job = job_or_404(jobs, req);
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Accel-Buffering", "no");
  res.set_chunked_content_provider("text/event-stream", [&jobs, job](size_t, httplib::DataSink& sink) {
    stream_events(jobs, job, sink);  // never throws
    sink.done();
    return true;
  });
}

struct Route {
  const char* method;
  const char* path;  // a regular expression over the whole path; groups are the handler's matches
  Handler handler;
};

// Every route. openapi.json documents the same set (test_openapi.py checks each is there).
const Route kRoutes[] = {
    {"GET", "/api/health", get_health},
    {"GET", "/api/openapi\\.json", get_openapi},
    {"GET", "/api/scenes", list_scenes},
    {"GET", "/api/scenes/([^/]+)", get_scene},
    {"PUT", "/api/scenes/([^/]+)", put_scene},
    {"DELETE", "/api/scenes/([^/]+)", delete_scene},
    {"POST", "/api/jobs/check", check_job},
    {"POST", "/api/jobs", submit_job},
    {"GET", "/api/jobs", list_jobs},
    {"GET", "/api/jobs/([^/]+)", get_job},
    {"DELETE", "/api/jobs/([^/]+)", delete_job},
    {"POST", "/api/jobs/([^/]+)/pause", pause_job},
    {"POST", "/api/jobs/([^/]+)/resume", resume_job},
    {"POST", "/api/jobs/([^/]+)/continue", continue_job},
    {"GET", "/api/jobs/([^/]+)/image\\.(png|exr)", get_image},
    {"GET", "/api/jobs/([^/]+)/pixels", get_pixels},
    {"GET", "/api/jobs/([^/]+)/focus", get_focus},
    {"GET", "/api/jobs/([^/]+)/events", watch_job},
};

}  // namespace

std::string allowed_methods(const std::string& path) {
  static const std::vector<std::regex> patterns = [] {
    std::vector<std::regex> out;
    for (const Route& r : kRoutes) out.emplace_back(r.path);
    return out;
  }();
  // A literal path ("/api/jobs/check") names its own methods, not those of a pattern it also fits.
  auto methods = [&](bool literal) {
    std::string allow;
    for (const char* m : {"GET", "POST", "PUT", "DELETE"})
      for (size_t i = 0; i < patterns.size(); ++i)
        if (kRoutes[i].method == std::string(m) && (std::strchr(kRoutes[i].path, '(') == nullptr) == literal &&
            std::regex_match(path, patterns[i])) {
          allow += (allow.empty() ? "" : ", ") + std::string(m);
          break;
        }
    return allow;
  };
  std::string literal = methods(true);
  return literal.empty() ? methods(false) : literal;
}

void install_routes(httplib::Server& svr, JobManager& jobs, const ApiOptions& options) {
  ApiOptions guards = options;
  guards.allowed_methods = allowed_methods;  // the 405's Allow header, from the same table
  install_guards(svr, guards);
  for (const Route& r : kRoutes) {
    Handler handler = r.handler;
    auto run = [&jobs, &options, handler](const Request& req, Response& res) {
      guarded(res, [&] { handler(jobs, options, req, res); });
    };
    std::string method = r.method;
    if (method == "GET") svr.Get(r.path, run);
    else if (method == "POST") svr.Post(r.path, run);
    else if (method == "PUT") svr.Put(r.path, run);
    else if (method == "DELETE") svr.Delete(r.path, run);
  }
}

}  // namespace srv
