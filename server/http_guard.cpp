// Request guards and error answers: see http_guard.h.
#include "http_guard.h"

#include <strings.h>

#include <cstdio>
#include <regex>

namespace srv {

namespace {

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

// A request line "TOKEN /path HTTP/1.x" whose method httplib does not route (it answers 400).
bool well_formed_unknown_method(const httplib::Request& req) {
  const std::string& m = req.method;
  if (m.empty() || m.size() > 20 || m.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZ") != std::string::npos) return false;
  for (const char* k : {"GET", "HEAD", "POST", "PUT", "PATCH", "DELETE", "OPTIONS", "CONNECT", "PRI"})
    if (m == k) return false;
  return (req.version == "HTTP/1.1" || req.version == "HTTP/1.0") && req.target.rfind("/", 0) == 0;
}

}  // namespace

bool authorized(const httplib::Request& req, const std::string& token) {
  return token.empty() || auth_failure(req, token).empty();
}

void send_json(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(dump_json(body), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& message, const std::string& field) {
  json err{{"status", status}, {"message", message}};
  if (!field.empty()) err["field"] = field;
  send_json(res, status, json{{"error", err}});
}

int http_status(JobErrorKind kind) {
  switch (kind) {
    case JobErrorKind::invalid: return 400;
    case JobErrorKind::not_found: return 404;
    case JobErrorKind::conflict: return 409;
    case JobErrorKind::queue_full: return 429;
    case JobErrorKind::shutting_down: return 503;
    case JobErrorKind::no_storage: return 507;
    case JobErrorKind::scene_broken: return 422;
    case JobErrorKind::read_only: return 403;
    case JobErrorKind::unsupported: return 422;
  }
  return 500;
}

void send_error_status(httplib::Response& res, int status, const std::string& message, const std::string& field,
                       const JobError::FieldErrors& errors) {
  if (errors.size() > 1) {
    json err{{"status", status}, {"message", message}, {"errors", json::array()}};
    if (!field.empty()) err["field"] = field;
    for (const auto& [f, m] : errors) {
      json e{{"message", m}};
      if (!f.empty()) e["field"] = f;
      err["errors"].push_back(e);
    }
    send_json(res, status, json{{"error", err}});
  } else {
    send_error(res, status, message, field);
  }
  if (status == 429 || status == 503) res.set_header("Retry-After", "5");
}

json parse_body(const httplib::Request& req) {
  std::string type = media_type(req.get_header_value("Content-Type"));
  if (type != "application/json")
    throw HttpError(415, "Content-Type must be application/json (got '" +
                            to_valid_utf8(clip_utf8(req.get_header_value("Content-Type"), 100)) + "')");
  try {
    return json::parse(req.body);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for 1e400
    throw HttpError(400, std::string("malformed JSON: ") + e.what());
  }
}

namespace {

std::function<size_t(const std::string&, const std::string&)> body_limit_of(const ApiOptions& o) {
  return [max_body = o.max_body, max_scene = o.max_scene_bytes](const std::string& method, const std::string& path) {
    return is_scene_upload(method, path) ? max_scene : max_body;
  };
}

std::string too_large(size_t limit) {
  return "the request body exceeds the limit of " +
         (limit >= (size_t(1) << 20) ? std::to_string(limit >> 20) + " MiB" : std::to_string(limit / 1024) + " KiB");
}

}  // namespace

void install_guards(httplib::Server& svr, const ApiOptions& options) {
  svr.set_payload_max_length(std::max(options.max_body, options.max_scene_bytes));
  // Runs after the head is read and before any body: the Host, the token, where the request comes
  // from, then the body's framing.
  svr.set_pre_routing_handler([token = options.token, body_limit = body_limit_of(options), hosts = options.hosts,
                               read_timeout = options.limits.request_timeout](const httplib::Request& req,
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
    // A DNS-rebinding page reaches a loopback server under a name of its own: answered for no name
    // but ours (RFC 9110 15.5.20: 421 Misdirected Request).
    if (req.get_header_value_count("Host") > 1 || !hosts.allows(req.get_header_value("Host")))
      return refuse(421, "this server does not answer for the host '" +
                             to_valid_utf8(clip_utf8(req.get_header_value("Host"), 100)) +
                             "' (start it with --allowed-host NAME to serve that name)");
    // httplib 0.11 builds a multi-range answer whole in memory, however many ranges are asked for
    // (Range: bytes=0-,0-,... multiplies a file): one range at most, on every route.
    if (req.get_header_value_count("Range") > 1 || count_ranges(req.get_header_value("Range")) > 1) {
      // httplib applies the parsed ranges to whatever answer goes out, this refusal included. The
      // Request is httplib's own non-const object, handed to this hook as const: clearing is safe.
      const_cast<httplib::Request&>(req).ranges.clear();
      res.set_header("Content-Range", "bytes */*");
      return refuse(416, "only a single byte range is served");
    }
    if (!token.empty() && needs_token(req.path)) {
      std::string why = auth_failure(req, token);
      if (!why.empty()) {
        res.set_header("WWW-Authenticate", why == kNoToken ? "Bearer realm=\"render-server\""
                                                           : "Bearer realm=\"render-server\", error=\"invalid_token\"");
        return refuse(401, why);
      }
    }
    // A page of another site must not change anything here (CSRF): refused whatever the body.
    bool changes_state = body_method || req.method == "DELETE";
    if (changes_state && cross_site_request(req.get_header_value("Origin"), req.get_header_value("Sec-Fetch-Site"),
                                            req.get_header_value("Host")))
      return refuse(403, "cross-site requests may not change anything here (Origin '" +
                             to_valid_utf8(clip_utf8(req.get_header_value("Origin"), 100)) + "', Sec-Fetch-Site '" +
                             to_valid_utf8(clip_utf8(req.get_header_value("Sec-Fetch-Site"), 40)) + "')");
    // One Content-Length of digits only: two that disagree, or "-1", would let a proxy in front and
    // this server split the stream into different requests (request smuggling).
    if (req.has_header("Content-Length")) {
      std::string len = req.get_header_value("Content-Length");
      if (req.get_header_value_count("Content-Length") != 1 || len.empty() || len.size() > 19 ||
          len.find_first_not_of("0123456789") != std::string::npos)
        return refuse(400, "Content-Length must be one non-negative integer");
      // Refused before a byte of it is read (httplib would read and discard it all first).
      const size_t max_body = body_limit(req.method, req.path);
      if (std::stoull(len) > max_body) return refuse(413, too_large(max_body));
      if (is_scene_upload(req.method, req.path)) {
        // Refused before its megabytes are read (httplib would also parse a form body itself).
        const std::string type = media_type(req.get_header_value("Content-Type"));
        if (!is_scene_media_type(type))
          return refuse(415, std::string("Content-Type must be the scene's own: ") + kSceneMediaTypes + " (got '" +
                                 to_valid_utf8(clip_utf8(type, 100)) + "')");
        // Its megabytes get time to arrive at 1 MiB/s or better, on top of --read-timeout.
        extend_request_deadline(read_timeout + std::stoull(len) / 1048576.0);
      }
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

  // Expect: 100-continue is answered before routing: a body over the limit gets its 413 instead of
  // an invitation to send it.
  svr.set_expect_100_continue_handler([body_limit = body_limit_of(options)](const httplib::Request& req,
                                                                           httplib::Response& res) {
    std::string len = req.get_header_value("Content-Length");
    const size_t max_body = body_limit(req.method, req.path);
    bool digits = !len.empty() && len.size() <= 19 && len.find_first_not_of("0123456789") == std::string::npos;
    if (digits && std::stoull(len) <= max_body) return 100;
    if (!digits) send_error(res, 400, "Content-Length must be one non-negative integer");
    else send_error(res, 413, too_large(max_body));
    close_after_response();
    res.set_header("Connection", "close");
    return res.status;
  });

  svr.set_error_handler([limits = options.limits, max_body = options.max_body,
                         allowed_methods = options.allowed_methods](const httplib::Request& req,
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
    // httplib answers a well-formed request with a method it does not serve (TRACE, QUERY, ...)
    // 400: it is 405, with the methods that are.
    if (res.status == 400 && failure == ReadFailure::none && well_formed_unknown_method(req)) {
      std::string allow = allowed_methods ? allowed_methods(req.path) : "";
      res.set_header("Allow", allow.empty() ? "GET, HEAD" : allow);
      send_error(res, 405, req.method + " is not allowed here (allowed: " + (allow.empty() ? "GET, HEAD" : allow) + ")");
      close_after_response();  // httplib read no body for it: none may be parsed as the next request
      res.set_header("Connection", "close");
    }
    if (ends_connection(res.status)) res.set_header("Connection", "close");
    if (!res.body.empty()) return;  // a handler already wrote its JSON error
    std::string allow = res.status == 404 && allowed_methods ? allowed_methods(req.path) : "";
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
    send_error(res, 500, to_valid_utf8(what));
  });
}

}  // namespace srv
