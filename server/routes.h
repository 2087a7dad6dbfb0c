// The HTTP API under /api (see openapi.json); the server's only HTTP-aware code besides main.cpp.
#pragma once

#include <httplib.h>

#include <string>

#include "jobs.h"

namespace srv {

void install_routes(httplib::Server& svr, JobManager& jobs, const std::string& openapi);

}  // namespace srv
