// Files under the data folder: safe reads, atomic writes, the folder lock, descriptor retries.
#include "job_store.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace srv {

std::string encode_sample_counts(const std::vector<uint32_t>& counts) {
  std::string out(counts.size() * 4, '\0');
  for (size_t i = 0; i < counts.size(); ++i)
    for (int b = 0; b < 4; ++b) out[4 * i + b] = char((counts[i] >> (8 * b)) & 0xff);
  return out;
}

bool decode_sample_counts(const std::string& bytes, size_t n, std::vector<uint32_t>& out) {
  if (bytes.size() != n * 4) return false;
  out.assign(n, 0);
  for (size_t i = 0; i < n; ++i)
    for (int b = 0; b < 4; ++b) out[i] |= uint32_t(uint8_t(bytes[4 * i + b])) << (8 * b);
  return true;
}

bool read_file(const std::string& path, std::string& out, std::string* why) {
  auto fail = [&](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  // O_NONBLOCK: opening a FIFO must not wait for a writer; O_NOFOLLOW: a link is refused.
  int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return fail(errno == ELOOP ? "a symbolic link" : std::strerror(errno));
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return fail("not a regular file");
  }
  out.clear();
  out.reserve(size_t(st.st_size));
  char buf[65536];
  for (;;) {
    ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      int err = errno;
      ::close(fd);
      return fail(std::strerror(err));
    }
    if (n == 0) break;
    out.append(buf, size_t(n));
  }
  ::close(fd);
  return true;
}

bool is_regular_file(const std::string& path) {
  struct stat st;
  return ::lstat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0;
}

void make_dirs(const std::string& path) {
  std::string cur;
  std::stringstream ss(path);
  std::string part;
  if (!path.empty() && path[0] == '/') cur = "/";
  while (std::getline(ss, part, '/')) {
    if (part.empty()) continue;
    cur += part + "/";
    if (::mkdir(cur.c_str(), 0755) != 0 && errno != EEXIST)
      throw std::runtime_error("cannot create the folder " + cur + ": " + std::strerror(errno));
  }
  struct stat st;
  if (::stat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    throw std::runtime_error(path + " is not a folder");
}

void write_file_atomic(const std::string& path, const std::string& data) {
  std::string tmp = path + ".tmp" + std::to_string(getpid());
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  size_t done = 0;
  int err = 0;
  while (done < data.size() && !err) {
    ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno != EINTR) err = errno;
    if (n > 0) done += size_t(n);
  }
  if (!err && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && !err) err = errno;
  if (err) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(err));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    err = errno;
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot move " + path + " into place: " + std::strerror(err));
  }
}

int remove_temp_files(const std::string& dir) {
  int removed = 0;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      std::string name = e->d_name;
      if (name.find(".tmp") != std::string::npos && std::remove((dir + "/" + name).c_str()) == 0) ++removed;
    }
    closedir(d);
  }
  return removed;
}

void retry_without_descriptors(const std::function<void()>& write, double seconds) {
  using clock = std::chrono::steady_clock;
  const std::string emfile = std::strerror(EMFILE), enfile = std::strerror(ENFILE);
  auto until = clock::now() + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(seconds));
  auto wait = std::chrono::milliseconds(50);
  for (;;) {
    try {
      write();
      return;
    } catch (const std::exception& e) {
      std::string what = e.what();
      bool no_fd = what.find(emfile) != std::string::npos || what.find(enfile) != std::string::npos;
      if (!no_fd || clock::now() + wait > until) throw;
      std::fprintf(stderr, "render-server: %s; retrying in %lld ms\n", what.c_str(), (long long)wait.count());
    }
    std::this_thread::sleep_for(wait);
    wait = std::min(wait * 2, std::chrono::milliseconds(2000));
  }
}

DataDirLock::DataDirLock(const std::string& dir) {
  std::string path = dir + "/.lock";
  m_fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (m_fd < 0) throw std::runtime_error("cannot open the lock file " + path + ": " + std::strerror(errno));
  if (::flock(m_fd, LOCK_EX | LOCK_NB) != 0) {
    int err = errno;
    char holder[32] = "";
    ssize_t n = ::pread(m_fd, holder, sizeof holder - 1, 0);
    ::close(m_fd);
    m_fd = -1;
    std::string pid = n > 0 ? std::string(holder, size_t(n)) : std::string();
    while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
    if (err == EWOULDBLOCK)
      throw std::runtime_error("the data folder " + dir + " is in use by another render-server" +
                               (pid.empty() ? std::string() : " (pid " + pid + ")") +
                               "; stop it or give this one its own --data");
    throw std::runtime_error("cannot lock the data folder " + dir + ": " + std::strerror(err));
  }
  // The holder's pid, for the message a second server prints (informative only: flock decides).
  std::string pid = std::to_string(getpid()) + "\n";
  if (::ftruncate(m_fd, 0) == 0 && ::pwrite(m_fd, pid.data(), pid.size(), 0) < 0) { /* best effort */ }
}

DataDirLock::~DataDirLock() {
  if (m_fd >= 0) ::close(m_fd);
}

}  // namespace srv
