// A job's image as clients see it while it renders: the Server-Sent Events stream (the whole image,
// then changed regions and status) and the whole-image PNG of a running job. Every encoding is made
// once and shared by all clients (a cache of the recently watched jobs), outside the mutex the render
// threads take.
#pragma once

#include <httplib.h>

#include <memory>
#include <string>

#include "jobs.h"

namespace srv {

// One watcher's event stream until the job ends, the client goes away or the server stops. Never
// throws: an error ends this stream (logged), never the server.
void stream_events(JobManager& jobs, const std::shared_ptr<Job>& job, httplib::DataSink& sink);

// The PNG of a job's current display image (a running or cancelled job), encoded at most once per
// published pass however many clients ask. Empty when the job has no image yet.
std::string current_png(Job& job);

// What serving images has cost since start (for /api/health).
struct StreamStats {
  uint64_t watchers = 0, png_encodes = 0, tile_events = 0;
};
StreamStats stream_stats();

}  // namespace srv
