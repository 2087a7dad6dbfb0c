// HTTP routes: thin handlers that validate, enqueue or copy a status snapshot; the job event
// stream (Server-Sent Events) with per-client tile bookkeeping so slow clients skip ahead.
#include "routes.h"

#include <strings.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>

#include "image.h"

namespace srv {

namespace {

void send_json(httplib::Response& res, int status, const json& body) {
  res.status = status;
  // replace: a message quoting a non-UTF-8 path (GET /api/%FF) must not throw.
  res.set_content(body.dump(-1, ' ', false, json::error_handler_t::replace), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& message, const std::string& field = "") {
  json err{{"status", status}, {"message", message}};
  if (!field.empty()) err["field"] = field;
  send_json(res, status, json{{"error", err}});
}

std::string base64(const std::string& in) {
  static const char* tbl = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
    out += tbl[v >> 18];
    out += tbl[(v >> 12) & 63];
    out += tbl[(v >> 6) & 63];
    out += tbl[v & 63];
  }
  if (i + 1 == in.size()) {
    uint32_t v = uint8_t(in[i]) << 16;
    out += tbl[v >> 18];
    out += tbl[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8);
    out += tbl[v >> 18];
    out += tbl[(v >> 12) & 63];
    out += tbl[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

json parse_body(const httplib::Request& req) {
  std::string ct = req.get_header_value("Content-Type");
  for (char& c : ct) c = char(std::tolower((unsigned char)c));  // media types are case-insensitive
  if (!ct.empty() && ct.find("application/json") == std::string::npos)
    throw ApiError(415, "Content-Type must be application/json");
  try {
    return json::parse(req.body);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for 1e400
    throw ApiError(400, std::string("malformed JSON: ") + e.what());
  }
}

// The methods each API path answers (keep in step with install_routes): a known path asked with
// another method gets 405 and an Allow header instead of 404.
std::string allowed_methods(const std::string& path) {
  static const std::pair<std::regex, const char*> table[] = {
      {std::regex("/api/(health|openapi\\.json|scenes)"), "GET"},
      {std::regex("/api/jobs"), "GET, POST"},
      {std::regex("/api/jobs/check"), "POST"},
      {std::regex("/api/jobs/[^/]+"), "GET, DELETE"},
      {std::regex("/api/jobs/[^/]+/(image\\.png|image\\.exr|focus|events)"), "GET"}};
  for (const auto& [re, allow] : table)
    if (std::regex_match(path, re)) return allow;
  return "";
}

// ---- access token ----

const char* const kNoToken = "this server requires a token: send 'Authorization: Bearer <token>'";

// Every /api call needs the token but the liveness probe; the page itself (/) does not.
bool needs_token(const std::string& path) {
  return (path == "/api" || path.rfind("/api/", 0) == 0) && path != "/api/health";
}

// Compares in time that depends only on the secret's length, never on where the first difference is.
bool same_secret(const std::string& given, const std::string& secret) {
  volatile unsigned char diff = given.size() != secret.size();
  for (size_t i = 0; i < secret.size(); ++i)
    diff = diff | (unsigned char)(secret[i] ^ (i < given.size() ? given[i] : 0));
  return diff == 0;
}

// Why a request is not authorised ("" when it is): the token comes from "Authorization: Bearer T",
// or, on the event-stream and image URLs only (EventSource and links cannot send headers), ?token=T.
std::string auth_failure(const httplib::Request& req, const std::string& token) {
  static const std::regex query_ok("/api/jobs/[^/]+/(events|image\\.png|image\\.exr)");
  if (req.has_header("Authorization")) {
    std::string auth = req.get_header_value("Authorization");
    if (auth.size() < 7 || strncasecmp(auth.c_str(), "Bearer ", 7) != 0)
      return "Authorization must be 'Bearer <token>'";
    size_t start = auth.find_first_not_of(' ', 7);
    return same_secret(start == std::string::npos ? "" : auth.substr(start), token) ? "" : "the token is not valid";
  }
  if (req.has_param("token")) {
    if (!std::regex_match(req.path, query_ok))
      return "a token in the query is accepted only on the event-stream and image URLs; send 'Authorization: Bearer <token>'";
    return same_secret(req.get_param_value("token"), token) ? "" : "the token is not valid";
  }
  return kNoToken;
}

// Runs a handler body, turning ApiError into its JSON error and anything else into a 500.
template <typename F>
void guarded(httplib::Response& res, F&& f) {
  try {
    f();
  } catch (const ApiError& e) {
    send_error(res, e.status(), e.what(), e.field());
    if (e.status() == 429 || e.status() == 503) res.set_header("Retry-After", "5");
  }
}

// One tile at its current version as base64 PNG text, encoded once and shared by every watcher.
// Returns false when the job has no such tile yet.
bool tile_png(Job& job, size_t idx, std::string& png, int& x, int& y, int& w, int& h, uint64_t& version) {
  std::vector<uint8_t> rgb;
  {
    std::lock_guard<std::mutex> lock(job.mutex);
    if (idx >= job.tile_version.size() || job.tile_version[idx] == 0) return false;
    version = job.tile_version[idx];
    x = int(idx % job.tiles_x) * job.tile_size;
    y = int(idx / job.tiles_x) * job.tile_size;
    w = std::min(job.tile_size, job.width - x);
    h = std::min(job.tile_size, job.height - y);
    if (job.tile_png_version[idx] == version) {
      png = job.tile_png[idx];
      return true;
    }
    rgb.resize(size_t(w) * h * 3);
    for (int r = 0; r < h; ++r)
      std::memcpy(&rgb[size_t(r) * w * 3], &job.display[(size_t(y + r) * job.width + x) * 3], size_t(w) * 3);
  }
  png = base64(pt::encode_png8(rgb, w, h));  // outside the lock: rendering never waits for encoding
  std::lock_guard<std::mutex> lock(job.mutex);
  if (job.tile_png_version[idx] < version) {
    job.tile_png[idx] = png;
    job.tile_png_version[idx] = version;
  }
  return true;
}

std::string sse(const std::string& event, const json& data, uint64_t id) {
  return "id: " + std::to_string(id) + "\nevent: " + event + "\ndata: " + data.dump() + "\n\n";
}

// One watcher's event stream: the whole current image first, then status and changed tiles as
// the job updates, newest state only (a slow client skips intermediate versions), until the job
// ends. Returns when the job ends, the client goes away, or the server stops.
void stream_events(JobManager& jobs, const std::shared_ptr<Job>& job, httplib::DataSink& sink) {
  std::vector<uint64_t> sent;
  uint64_t seen = 0;
  bool first = true;
  // Watchers cost the renderer CPU: tiles are batched per round (a round at most every 40 ms) and
  // a status event goes out at most every 250 ms unless the state changes.
  using clock = std::chrono::steady_clock;
  const auto round_gap = std::chrono::milliseconds(40), status_gap = std::chrono::milliseconds(250);
  clock::time_point last_status;
  std::string last_state;
  auto write = [&](const std::string& s) { return sink.write(s.data(), s.size()); };
  if (!write("retry: 2000\n\n")) return;
  for (;;) {
    json status;
    uint64_t version;
    bool final_state, has_image, png_on_disk = false;
    std::vector<uint8_t> display;
    int width = 0, height = 0;
    {
      std::unique_lock<std::mutex> lock(job->mutex);
      bool changed = job->changed.wait_for(lock, std::chrono::seconds(15),
                                           [&] { return job->version != seen || jobs.stopping(); });
      if (jobs.stopping()) return;
      if (!changed) {
        lock.unlock();
        if (!write(": keep-alive\n\n")) return;
        continue;
      }
      version = job->version;
      final_state = is_final(job->state);
      if (first || final_state || last_state != job_state_name(job->state) || clock::now() - last_status >= status_gap) {
        status = jobs.status_json(*job, false);
        if (!job->history.empty()) {
          const ErrorPoint& p = job->history.back();
          status["error_point"] = {{"seconds", p.seconds}, {"spp", p.spp}, {"error", p.error}};
        }
        last_state = job_state_name(job->state);
        last_status = clock::now();
      }
      has_image = job->has_image;
      if (sent.size() != job->tile_version.size()) sent.assign(job->tile_version.size(), 0);
      if (first && (has_image || job->state == JobState::done)) {
        display = job->display;  // empty for a job finished before a restart: its PNG is on disk
        png_on_disk = !has_image;
        width = job->width;
        height = job->height;
      }
    }
    if (first) {
      // A late or reconnecting client starts from the current picture.
      std::string png;
      if (png_on_disk) read_file(jobs.job_dir(job->id) + "/image.png", png);
      else if (!display.empty()) png = pt::encode_png8(display, width, height);
      if (!png.empty()) {
        if (!write(sse("image", {{"width", width}, {"height", height}, {"png", base64(png)}}, version))) return;
        std::lock_guard<std::mutex> lock(job->mutex);
        for (size_t i = 0; i < sent.size() && i < job->tile_version.size(); ++i) sent[i] = std::min(job->tile_version[i], version);
      }
      first = false;
    }
    if (!status.is_null() && !write(sse("status", status, version))) return;
    bool sent_tiles = false;
    for (size_t i = 0; i < sent.size(); ++i) {
      uint64_t tv;
      {
        std::lock_guard<std::mutex> lock(job->mutex);
        tv = i < job->tile_version.size() ? job->tile_version[i] : 0;
      }
      if (tv <= sent[i]) continue;
      std::string png;
      int x, y, w, h;
      uint64_t v;
      if (!tile_png(*job, i, png, x, y, w, h, v)) continue;
      // The id is this round's version, not the tile's: ids never go back within a stream.
      if (!write(sse("tile", {{"x", x}, {"y", y}, {"w", w}, {"h", h}, {"png", png}}, version))) return;
      sent[i] = v;
      sent_tiles = true;
    }
    seen = version;
    if (final_state) {
      write(sse("end", {{"state", status["state"]}}, version));
      return;
    }
    // After a round that sent tiles, let more accumulate, but wake at once for a change of state.
    if (!sent_tiles) continue;
    std::unique_lock<std::mutex> lock(job->mutex);
    job->changed.wait_for(lock, round_gap, [&] {
      return last_state != job_state_name(job->state) || is_final(job->state) || jobs.stopping();
    });
  }
}

}  // namespace

void install_routes(httplib::Server& svr, JobManager& jobs, const ApiOptions& options) {
  const std::string openapi = options.openapi;
  svr.set_payload_max_length(options.max_body);
  // Runs after the head is read and before any body: the token first, then the body's framing.
  svr.set_pre_routing_handler([token = options.token, max_body = options.max_body](const httplib::Request& req,
                                                                                   httplib::Response& res) {
    using Result = httplib::Server::HandlerResponse;
    // Methods whose body httplib reads (PRI: an HTTP/2 preface, read to the end of the connection).
    bool body_method = req.method == "POST" || req.method == "PUT" || req.method == "PATCH" || req.method == "PRI";
    auto refuse = [&](int status, const std::string& message) {
      send_error(res, status, message);
      if (body_method || req.has_header("Content-Length") || req.has_header("Transfer-Encoding")) {
        close_after_response();  // the body stays unread: it must not be parsed as the next request
        res.set_header("Connection", "close");
      }
      return Result::Handled;
    };
    // "/index.html%00.js" would open index.html: C file APIs stop at the NUL.
    if (req.path.find('\0') != std::string::npos) return refuse(400, "the path contains a NUL byte");
    if (!token.empty() && needs_token(req.path)) {
      std::string why = auth_failure(req, token);
      if (!why.empty()) {
        res.set_header("WWW-Authenticate", why == kNoToken ? "Bearer realm=\"render-server\""
                                                           : "Bearer realm=\"render-server\", error=\"invalid_token\"");
        return refuse(401, why);
      }
    }
    // One Content-Length of digits only: two that disagree, or "-1", would let a proxy in front and
    // this server split the stream into different requests (request smuggling).
    if (req.has_header("Content-Length")) {
      std::string len = req.get_header_value("Content-Length");
      if (req.get_header_value_count("Content-Length") != 1 || len.empty() || len.size() > 19 ||
          len.find_first_not_of("0123456789") != std::string::npos)
        return refuse(400, "Content-Length must be one non-negative integer");
      // Refused before a byte of it is read (httplib would read and discard it all first).
      if (std::stoull(len) > max_body)
        return refuse(413, "the request body exceeds the limit of " + std::to_string(max_body / 1024) + " KiB");
    }
    if (!body_method) {
      // httplib never reads a GET's (or HEAD's, OPTIONS') body: close after answering rather than
      // parse it as the next request.
      if (req.has_header("Transfer-Encoding") || (req.has_header("Content-Length") && req.method != "DELETE" &&
                                                  req.get_header_value("Content-Length") != "0")) {
        close_after_response();
        res.set_header("Connection", "close");
      }
      return Result::Unhandled;
    }
    // httplib 0.11 reads a chunked body whole, past the 64 KiB payload limit: only Content-Length
    // framing is accepted. Without either it would wait for the read timeout: refuse at once.
    if (req.has_header("Transfer-Encoding"))
      return refuse(411, "Transfer-Encoding is not accepted: send the body with a Content-Length");
    if (!req.has_header("Content-Length")) return refuse(411, "Content-Length is required");
    return Result::Unhandled;
  });

  svr.Get("/api/health", [&](const httplib::Request&, httplib::Response& res) {
    size_t queued = 0, running = 0;
    for (auto& j : jobs.list()) {
      std::lock_guard<std::mutex> lock(j->mutex);
      queued += j->state == JobState::queued;
      running += j->state == JobState::running;
    }
    json health{{"status", "ok"}, {"queued", queued}, {"running", running}, {"rendering", jobs.backend_name()}};
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
      std::string data;
      pt::ImageRGB img;
      {
        std::lock_guard<std::mutex> lock(job->mutex);
        bool done = job->state == JobState::done;
        if (!done && !job->has_image) throw ApiError(404, "job has no image yet (state " + std::string(job_state_name(job->state)) + ")");
        if (!done || !read_file(jobs.job_dir(job->id) + "/image." + ext, data)) {
          if (!job->has_image) throw ApiError(404, "the job's image is missing");
          img.width = job->width;
          img.height = job->height;
          if (ext == "png") {
            std::vector<uint8_t> rgb = job->display;
            data.clear();
            img.pixels.clear();
            res.set_header("Cache-Control", "no-store");
            std::string png = pt::encode_png8(rgb, img.width, img.height);
            res.set_content(png, type);
            return;
          }
          img.pixels.resize(size_t(img.width) * img.height);
          std::memcpy(static_cast<void*>(img.pixels.data()), job->linear.data(), img.pixels.size() * sizeof(pt::Vec3));
        }
      }
      if (data.empty()) data = pt::encode_exr(img);
      res.set_header("Cache-Control", "no-store");
      res.set_content(data, type);
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
    auto job = jobs.get(req.matches[1]);
    if (!job) return send_error(res, 404, "no job '" + std::string(req.matches[1]) + "'");
    res.set_header("Cache-Control", "no-cache");
    res.set_header("X-Accel-Buffering", "no");
    res.set_chunked_content_provider("text/event-stream", [&jobs, job](size_t, httplib::DataSink& sink) {
      stream_events(jobs, job, sink);
      sink.done();
      return true;
    });
  });

  svr.set_error_handler([limits = options.limits, max_body = options.max_body](const httplib::Request& req,
                                                                              httplib::Response& res) {
    // httplib answers 400 (413 for a Content-Length over the limit) when reading a request fails:
    // say why where the connection layer knows.
    ReadFailure failure = current_read_failure();
    if (failure == ReadFailure::timeout && res.status == 400) {
      char msg[120];
      std::snprintf(msg, sizeof msg, "the request was not received within %g s", limits.request_timeout);
      send_error(res, 408, msg);
    } else if (failure == ReadFailure::head_too_large && res.status == 400) {
      send_error(res, 431, "the request line and headers exceed " + std::to_string(limits.max_head_bytes) + " bytes");
    } else if (failure == ReadFailure::body_too_large && (res.status == 400 || res.status == 413)) {
      send_error(res, 413, "the request body exceeds the limit of " + std::to_string(max_body / 1024) + " KiB");
    }
    if (ends_connection(res.status)) res.set_header("Connection", "close");
    if (!res.body.empty()) return;  // a handler already wrote its JSON error
    std::string allow = res.status == 404 ? allowed_methods(req.path) : "";
    if (!allow.empty()) {
      res.set_header("Allow", allow);
      return send_error(res, 405, req.method + " is not allowed on " + req.path + " (allowed: " + allow + ")");
    }
    if (req.path.rfind("/api/", 0) == 0 || res.status != 404)
      send_error(res, res.status, res.status == 404 ? "no such endpoint: " + req.method + " " + req.path
                                                    : "request rejected (" + std::to_string(res.status) + ")");
  });

  svr.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "internal error";
    try {
      if (ep) std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    send_error(res, 500, what);
  });
}

}  // namespace srv
