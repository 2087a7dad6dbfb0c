// An LD_PRELOAD library that makes writes to some files lose bytes while reporting success, as a
// disk that filled up did to OpenImageIO's PNG writer: after the first SHORT_WRITE_KEEP bytes of a
// file whose path contains SHORT_WRITE_MATCH, write() and fwrite() drop what they are given and
// say it was written. tests/server/test_hardening.py uses it to show that such an image is never
// served as done.

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { kMaxFd = 65536 };
static long long g_written[kMaxFd];
static int g_fd_checked[kMaxFd];  // 0 unknown, 1 matches, 2 does not

static int matches(int fd) {
  const char* match = getenv("SHORT_WRITE_MATCH");
  if (!match || fd < 0 || fd >= kMaxFd) return 0;
  char link[64], path[4096];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  ssize_t n = readlink(link, path, sizeof path - 1);
  if (n <= 0) return 0;
  path[n] = '\0';
  int hit = strstr(path, match) != NULL;
  if (hit && g_fd_checked[fd] != 1) g_written[fd] = 0;  // a new file on a reused descriptor
  g_fd_checked[fd] = hit ? 1 : 2;
  return hit;
}

// How many of `size` bytes really go to the file.
static size_t kept(int fd, size_t size) {
  if (!matches(fd)) return size;
  long long keep = getenv("SHORT_WRITE_KEEP") ? atoll(getenv("SHORT_WRITE_KEEP")) : 100;
  long long room = keep - g_written[fd];
  size_t n = room <= 0 ? 0 : (size_t)room < size ? (size_t)room : size;
  g_written[fd] += (long long)size;
  return n;
}

ssize_t write(int fd, const void* buf, size_t size) {
  static ssize_t (*real)(int, const void*, size_t);
  if (!real) real = (ssize_t(*)(int, const void*, size_t))dlsym(RTLD_NEXT, "write");
  size_t n = kept(fd, size);
  if (n > 0 && real(fd, buf, n) < 0) return -1;
  return (ssize_t)size;
}

size_t fwrite(const void* ptr, size_t size, size_t count, FILE* stream) {
  static size_t (*real)(const void*, size_t, size_t, FILE*);
  if (!real) real = (size_t(*)(const void*, size_t, size_t, FILE*))dlsym(RTLD_NEXT, "fwrite");
  size_t bytes = size * count, n = kept(fileno(stream), bytes);
  if (n > 0) real(ptr, 1, n, stream);
  return count;
}
