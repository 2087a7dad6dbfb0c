// HTTP routes: thin handlers that validate, enqueue or copy a status snapshot. What every request
// passes first is http_guard.cpp; the event stream and shared image encodings, event_stream.cpp.
#include "routes.h"

#include <cmath>
#include <cstring>

#include "event_stream.h"
#include "image.h"

namespace srv {

void install_routes(httplib::Server& svr, JobManager& jobs, const ApiOptions& options) {
  const std::string openapi = options.openapi;
  install_guards(svr, options);

  svr.Get("/api/health", [&](const httplib::Request&, httplib::Response& res) {
    size_t queued = 0, running = 0;
    for (auto& j : jobs.list()) {
      std::lock_guard<std::mutex> lock(j->mutex);
      queued += j->state == JobState::queued;
      running += j->state == JobState::running;
    }
    json health{{"status", "ok"}, {"queued", queued}, {"running", running}, {"rendering", jobs.backend_name()}};
    StreamStats st = stream_stats();
    health["stream"] = {{"watchers", st.watchers}, {"png_encodes", st.png_encodes}, {"tile_events", st.tile_events}};
    int workers = jobs.live_workers();
    if (workers >= 0) health["workers"] = workers;
    send_json(res, 200, health);
  });

  svr.Get("/api/openapi.json", [openapi](const httplib::Request&, httplib::Response& res) {
    res.set_content(openapi, "application/json");
  });

  svr.Get("/api/scenes", [&](const httplib::Request&, httplib::Response& res) {
    send_json(res, 200, {{"scenes", jobs.scenes().list()}, {"defaults", job_spec_defaults()}});
  });

  svr.Post("/api/jobs/check", [&](const httplib::Request& req, httplib::Response& res) {
    guarded(res, [&] {
      JobSpec spec = jobs.check(parse_body(req));
      send_json(res, 200, {{"valid", true}, {"spec", job_spec_to_json(spec)}});
    });
  });

  svr.Post("/api/jobs", [&](const httplib::Request& req, httplib::Response& res) {
    guarded(res, [&] {
      std::string key = req.get_header_value("Idempotency-Key");
      if (key.size() > 200) throw ApiError(400, "Idempotency-Key is longer than 200 characters", "Idempotency-Key");
      if (!valid_utf8(key)) throw ApiError(400, "Idempotency-Key is not valid UTF-8", "Idempotency-Key");
      auto [job, created] = jobs.submit(parse_body(req), key);
      std::lock_guard<std::mutex> lock(job->mutex);
      res.set_header("Location", "/api/jobs/" + job->id);
      send_json(res, created ? 201 : 200, jobs.status_json(*job));
    });
  });

  svr.Get("/api/jobs", [&](const httplib::Request&, httplib::Response& res) {
    json list = json::array();
    for (auto& j : jobs.list()) {
      std::lock_guard<std::mutex> lock(j->mutex);
      list.push_back(jobs.status_json(*j, false));
    }
    send_json(res, 200, {{"jobs", list}});
  });

  svr.Get(R"(/api/jobs/([^/]+))", [&](const httplib::Request& req, httplib::Response& res) {
    auto job = jobs.get(req.matches[1]);
    if (!job) return send_error(res, 404, "no job '" + std::string(req.matches[1]) + "'");
    std::lock_guard<std::mutex> lock(job->mutex);
    send_json(res, 200, jobs.status_json(*job));
  });

  svr.Delete(R"(/api/jobs/([^/]+))", [&](const httplib::Request& req, httplib::Response& res) {
    guarded(res, [&] {
      jobs.cancel(req.matches[1]);
      auto job = jobs.get(req.matches[1]);
      std::lock_guard<std::mutex> lock(job->mutex);
      send_json(res, 200, jobs.status_json(*job));
    });
  });

  svr.Get(R"(/api/jobs/([^/]+)/image\.(png|exr))", [&](const httplib::Request& req, httplib::Response& res) {
    guarded(res, [&] {
      auto job = jobs.get(req.matches[1]);
      if (!job) throw ApiError(404, "no job '" + std::string(req.matches[1]) + "'");
      std::string ext = req.matches[2];
      const char* type = ext == "png" ? "image/png" : "image/x-exr";
      bool done, has_image;
      std::string state;
      {
        std::lock_guard<std::mutex> lock(job->mutex);
        done = job->state == JobState::done;
        has_image = job->has_image;
        state = job_state_name(job->state);
      }
      if (!done && !has_image) throw ApiError(404, "job has no image yet (state " + state + ")");
      res.set_header("Cache-Control", "no-store");
      std::string data;
      // A done job's files (a regular file only: never a link or a FIFO someone put there).
      if (done && read_file(jobs.job_dir(job->id) + "/image." + ext, data)) return res.set_content(data, type);
      if (!has_image) throw ApiError(404, "the job's image is missing");
      if (ext == "png") return res.set_content(current_png(*job), type);  // encoded once a pass for all
      pt::ImageRGB img;
      {
        std::lock_guard<std::mutex> lock(job->mutex);
        img.width = job->width;
        img.height = job->height;
        img.pixels.resize(size_t(img.width) * img.height);
        std::memcpy(static_cast<void*>(img.pixels.data()), job->linear.data(), img.pixels.size() * sizeof(pt::Vec3));
      }
      res.set_content(pt::encode_exr(img), type);  // outside the mutex the render threads take
    });
  });

  svr.Get(R"(/api/jobs/([^/]+)/focus)", [&](const httplib::Request& req, httplib::Response& res) {
    guarded(res, [&] {
      auto job = jobs.get(req.matches[1]);
      if (!job) throw ApiError(404, "no job '" + std::string(req.matches[1]) + "'");
      auto coord = [&](const char* name) {
        if (!req.has_param(name)) throw ApiError(400, std::string("query parameter '") + name + "' is required", name);
        std::string v = req.get_param_value(name);
        char* end = nullptr;
        double d = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != '\0' || !std::isfinite(d))
          throw ApiError(400, std::string("query parameter '") + name + "' must be a number", name);
        return d;
      };
      double x = coord("x"), y = coord("y");
      double d = jobs.focus_distance(*job, x, y);
      send_json(res, 200, {{"x", x}, {"y", y}, {"distance", std::isfinite(d) ? json(d) : json(nullptr)}});
    });
  });

  svr.Get(R"(/api/jobs/([^/]+)/events)", [&](const httplib::Request& req, httplib::Response& res) {
    auto job = jobs.get(req.matches[1]);  // the id is hex digits only, or no job
    if (!job) return send_error(res, 404, "no job '" + std::string(req.matches[1]) + "'");
    res.set_header("Cache-Control", "no-cache");
    res.set_header("X-Accel-Buffering", "no");
    res.set_chunked_content_provider("text/event-stream", [&jobs, job](size_t, httplib::DataSink& sink) {
      stream_events(jobs, job, sink);
      sink.done();
      return true;
    });
  });
}

}  // namespace srv
