// Checkpoints of a long render: the film, the session's counts and the driver's next pass, written
// atomically between passes. A render restored from one continues exactly where it stood: each
// sample's random numbers depend only on the seed, the pixel and the sample index, and the film
// holds every statistic the stop rules and the error estimate read, so the finished image is the
// uninterrupted render's, bit for bit.
#pragma once

#include <string>

#include "session.h"

namespace pt {

// What a checkpoint must match to be resumed: the scene file's bytes and every option that changes
// the image (not the thread count, tile size or the limits, which only decide when it stops).
std::string render_fingerprint(const std::string& scene_bytes, const RenderParams& params);

// Writes the checkpoint to `path` (a temporary file, flushed to disk, then renamed over it).
void save_checkpoint(const std::string& path, const std::string& fingerprint, const RenderSession& session,
                     const ProgressiveDriver& driver);
// Restores a fresh session and driver from `path`: false when there is no file there; throws
// std::runtime_error naming the file when it is not a checkpoint of this render or is damaged.
bool restore_checkpoint(const std::string& path, const std::string& fingerprint, RenderSession& session,
                        ProgressiveDriver& driver);

}  // namespace pt
