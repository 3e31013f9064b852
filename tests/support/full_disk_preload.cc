// A disk that fills up, for tests (LD_PRELOAD): writes to files under the directory
// DIVERSE_FULL_DISK_DIR share a budget of DIVERSE_FULL_DISK_BYTES bytes; once it is
// spent, a write is cut short and the next one fails with ENOSPC, as on a full file
// system. With DIVERSE_FULL_DISK_STALL=1 the write that meets the end of the budget
// stops for good instead (a writer frozen mid-write, for a test to kill at that moment).
// Writes elsewhere (stdout, other directories) are untouched.
#include <dlfcn.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/uio.h>
#include <unistd.h>

#include <atomic>

namespace {

std::atomic<long long> spent{0};

// How many of `n` bytes to `fd` may be written: n when it is not under the directory.
size_t allowed(int fd, size_t n) {
  const char* dir = getenv("DIVERSE_FULL_DISK_DIR");
  const char* bytes = getenv("DIVERSE_FULL_DISK_BYTES");
  if (dir == nullptr || bytes == nullptr) return n;
  char link[64], path[4096];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t len = readlink(link, path, sizeof path - 1);
  if (len <= 0) return n;
  path[len] = '\0';
  if (strncmp(path, dir, strlen(dir)) != 0) return n;
  const long long budget = atoll(bytes);
  const long long before = spent.fetch_add(static_cast<long long>(n));
  const char* stall = getenv("DIVERSE_FULL_DISK_STALL");
  if (stall != nullptr && stall[0] == '1' && before + static_cast<long long>(n) > budget) {
    for (;;) pause();
  }
  if (before >= budget) return 0;
  return static_cast<size_t>(before + static_cast<long long>(n) <= budget ? static_cast<long long>(n)
                                                                            : budget - before);
}

}  // namespace

extern "C" ssize_t write(int fd, const void* buf, size_t n) {
  using Write = ssize_t (*)(int, const void*, size_t);
  static const Write real = reinterpret_cast<Write>(dlsym(RTLD_NEXT, "write"));
  const size_t ok = allowed(fd, n);
  if (ok == 0 && n > 0) {
    errno = ENOSPC;
    return -1;
  }
  return real(fd, buf, ok);
}

extern "C" ssize_t writev(int fd, const struct iovec* iov, int count) {
  using Writev = ssize_t (*)(int, const struct iovec*, int);
  static const Writev real = reinterpret_cast<Writev>(dlsym(RTLD_NEXT, "writev"));
  size_t n = 0;
  for (int i = 0; i < count; ++i) n += iov[i].iov_len;
  const size_t ok = allowed(fd, n);
  if (ok == n) return real(fd, iov, count);
  if (ok == 0 && n > 0) {
    errno = ENOSPC;
    return -1;
  }
  // Cut short: write the first `ok` bytes only.
  size_t left = ok;
  ssize_t total = 0;
  for (int i = 0; i < count && left > 0; ++i) {
    const size_t part = iov[i].iov_len < left ? iov[i].iov_len : left;
    const ssize_t w = write(fd, iov[i].iov_base, part);
    if (w < 0) return total > 0 ? total : w;
    total += w;
    left -= static_cast<size_t>(w);
  }
  return total;
}
