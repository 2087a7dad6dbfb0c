// What every request passes before a route sees it, and how errors are answered: the Host check
// (DNS rebinding), the access token, cross-site refusal for state-changing requests (CSRF), body
// framing and size, Range limits, and JSON error bodies for whatever httplib itself refuses.
#pragma once

#include <httplib.h>

#include <functional>
#include <string>

#include "connection.h"
#include "job_spec.h"
#include "request_policy.h"

namespace srv {

struct ApiOptions {
  std::string openapi;      // the contract, served at /api/openapi.json
  std::string token;        // when set, required on every /api call but /api/health
  ConnectionLimits limits;  // named in the 408 / 431 messages
  size_t max_body = 64 * 1024;  // request body bytes (413 beyond)
  size_t max_scene_bytes = size_t(64) << 20;  // an uploaded scene's bytes (PUT /api/scenes/{name})
  HostPolicy hosts;         // which Host headers are answered (421 otherwise)
  // The methods a path answers ("" for none): a known path asked with another method gets 405 and
  // this in its Allow header. install_routes sets it from its route table.
  std::function<std::string(const std::string&)> allowed_methods;
};

// A scene upload, whose body may be as large as max_scene_bytes (other bodies: max_body).
inline bool is_scene_upload(const std::string& method, const std::string& path) {
  return method == "PUT" && path.rfind("/api/scenes/", 0) == 0;
}
// An upload's media type must be a scene's own: none a browser sends cross-site without asking.
inline bool is_scene_media_type(const std::string& type) {
  return type == "model/gltf-binary" || type == "model/gltf+json" || type == "model/vnd.collada+xml" ||
         type == "application/octet-stream";
}
constexpr const char* kSceneMediaTypes =
    "model/gltf-binary, model/gltf+json, model/vnd.collada+xml or application/octet-stream";

void send_json(httplib::Response& res, int status, const json& body);
void send_error(httplib::Response& res, int status, const std::string& message, const std::string& field = "");

// The body of a state-changing request as JSON: its media type must be application/json exactly
// (415 otherwise: a browser sends text/plain or a form cross-site without asking first), and it
// must parse (400).
json parse_body(const httplib::Request& req);

// An error only the HTTP layer raises (a header, a query parameter, the body), with its status.
class HttpError : public std::runtime_error {
 public:
  HttpError(int status, std::string message, std::string field = "")
      : std::runtime_error(std::move(message)), m_status(status), m_field(std::move(field)) {}
  int status() const { return m_status; }
  const std::string& field() const { return m_field; }

 private:
  int m_status;
  std::string m_field;
};

// The HTTP status that answers each kind of job-service error.
int http_status(JobErrorKind kind);

// Answers an error with its JSON body (and Retry-After where retrying later helps).
// `errors`: every invalid field when a request has several (error.errors).
void send_error_status(httplib::Response& res, int status, const std::string& message, const std::string& field,
                       const JobError::FieldErrors& errors = {});

// Runs a handler body, turning HttpError and JobError into their JSON errors and any other
// exception into a 500 (503 when memory ran out): nothing thrown leaves a handler.
template <typename F>
void guarded(httplib::Response& res, F&& f) {
  try {
    f();
  } catch (const HttpError& e) {
    send_error_status(res, e.status(), e.what(), e.field());
  } catch (const JobError& e) {
    send_error_status(res, http_status(e.kind()), e.what(), e.field(), e.errors());
  } catch (const std::bad_alloc&) {
    send_error(res, 503, "the server is out of memory for this request; retry later");
  } catch (const std::exception& e) {
    send_error(res, 500, to_valid_utf8(e.what()));
  }
}

// Installs the pre-routing checks, the Expect: 100-continue answer, the error and exception
// handlers on `svr`.
void install_guards(httplib::Server& svr, const ApiOptions& options);
// Whether the request carries the server's --token (always true without one).
bool authorized(const httplib::Request& req, const std::string& token);

}  // namespace srv
