// The HTTP API under /api (see openapi.json); the server's only HTTP-aware code besides main.cpp
// and connection.cpp.
#pragma once

#include <httplib.h>

#include <string>

#include "connection.h"
#include "jobs.h"

namespace srv {

struct ApiOptions {
  std::string openapi;      // the contract, served at /api/openapi.json
  std::string token;        // when set, required on every /api call but /api/health
  ConnectionLimits limits;  // named in the 408 / 431 messages
  size_t max_body = 64 * 1024;  // request body bytes (413 beyond)
};

void install_routes(httplib::Server& svr, JobManager& jobs, const ApiOptions& options);

}  // namespace srv
