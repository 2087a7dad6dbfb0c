// The job service's disk layer: files written atomically (temp name, fsync, rename), read only when
// they are regular files reached without following a link, the data folder's exclusive lock, and
// retries of writes that failed for want of a file descriptor.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace srv {

// Reads a whole regular file; false (and `why` set) when it is missing, a link, a FIFO, a device,
// a folder, or cannot be read. Never blocks on a FIFO and never follows a symlink in the last
// component: a job folder's files are the server's own, whatever someone put in their place.
bool read_file(const std::string& path, std::string& out, std::string* why = nullptr);
// True when `path` is a regular file (not a link to one) of at least one byte.
bool is_regular_file(const std::string& path);

// A finished job's samples.bin: each pixel's sample count, uint32 little-endian, rows top to bottom
// (what GET /pixels needs beside image.exr once the image is no longer in memory).
std::string encode_sample_counts(const std::vector<uint32_t>& counts);
// False when `bytes` is not `n` counts.
bool decode_sample_counts(const std::string& bytes, size_t n, std::vector<uint32_t>& out);

// Creates `path` and its parents; throws naming the folder and the system's reason (read-only file
// system, permission denied, ...).
void make_dirs(const std::string& path);
// Writes a whole file under a temp name, flushes it to the disk and renames it into place: readers,
// and a server restarted after a crash, never see a partial file. Throws naming the file and why.
void write_file_atomic(const std::string& path, const std::string& data);
// Removes the temp files a killed process left in `dir` (job.json.tmp<pid>, .image.exr.tmp<pid>-<n>);
// returns how many.
int remove_temp_files(const std::string& dir);

// Runs `write`, and while it fails for want of a file descriptor (EMFILE, ENFILE: a connection
// flood) retries it for up to `seconds`, so that a finished render is not lost to a passing flood.
// Other errors, and the last one, propagate.
void retry_without_descriptors(const std::function<void()>& write, double seconds = 30);

// An exclusive lock on a data folder (flock on <dir>/.lock, released when the process ends, even
// by kill -9). Two servers on one folder would render the same jobs and undo each other's cancels.
class DataDirLock {
 public:
  // Throws with a message naming the folder (and the holder's pid when known) if another process
  // holds it.
  explicit DataDirLock(const std::string& dir);
  ~DataDirLock();
  DataDirLock(const DataDirLock&) = delete;
  DataDirLock& operator=(const DataDirLock&) = delete;

 private:
  int m_fd = -1;
};

}  // namespace srv
