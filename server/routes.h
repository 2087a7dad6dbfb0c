// The HTTP API under /api (see openapi.json); the server's only HTTP-aware code besides main.cpp
// and connection.cpp.
#pragma once

#include <httplib.h>

#include <string>

#include "http_guard.h"
#include "jobs.h"

namespace srv {

void install_routes(httplib::Server& svr, JobManager& jobs, const ApiOptions& options);

}  // namespace srv
