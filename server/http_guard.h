// What every request passes before a route sees it, and how errors are answered: the Host check
// (DNS rebinding), the access token, cross-site refusal for state-changing requests (CSRF), body
// framing and size, Range limits, and JSON error bodies for whatever httplib itself refuses.
#pragma once

#include <httplib.h>

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
  HostPolicy hosts;         // which Host headers are answered (421 otherwise)
};

void send_json(httplib::Response& res, int status, const json& body);
void send_error(httplib::Response& res, int status, const std::string& message, const std::string& field = "");

// The body of a state-changing request as JSON: its media type must be application/json exactly
// (415 otherwise: a browser sends text/plain or a form cross-site without asking first), and it
// must parse (400).
json parse_body(const httplib::Request& req);

// Runs a handler body, turning ApiError into its JSON error and any other exception into a 500:
// nothing thrown leaves a handler.
template <typename F>
void guarded(httplib::Response& res, F&& f) {
  try {
    f();
  } catch (const ApiError& e) {
    send_error(res, e.status(), e.what(), e.field());
    if (e.status() == 429 || e.status() == 503) res.set_header("Retry-After", "5");
  } catch (const std::bad_alloc&) {
    send_error(res, 503, "the server is out of memory for this request; retry later");
  } catch (const std::exception& e) {
    send_error(res, 500, e.what());
  }
}

// Installs the pre-routing checks, the Expect: 100-continue answer, the error and exception
// handlers on `svr`.
void install_guards(httplib::Server& svr, const ApiOptions& options);

}  // namespace srv
