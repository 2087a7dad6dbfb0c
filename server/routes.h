// The HTTP API under /api (see openapi.json): its routes, and the guards every request passes
// (http_guard.h). The HTTP-aware code is this, http_guard.cpp, event_stream.cpp, connection.cpp
// and main.cpp; the job service below them speaks in JobError, never in statuses.
#pragma once

#include <httplib.h>

#include <string>

#include "http_guard.h"
#include "jobs.h"

namespace srv {

// Installs the guards and every route; `options` must outlive the server.
void install_routes(httplib::Server& svr, JobManager& jobs, const ApiOptions& options);
// The methods the routes answer on `path`, as an Allow header lists them ("" when none).
std::string allowed_methods(const std::string& path);

}  // namespace srv
