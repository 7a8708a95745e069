// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include "syscall_faults.h"

#include <atomic>
#include <cerrno>
#include <mutex>

#include <dlfcn.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace lumx_faults {
namespace {

std::mutex g_mutex;  // writes in the tests are single-threaded; the lock keeps the counters exact anyway
Fault g_fault;
std::uint64_t g_written = 0;
std::atomic<int> g_failures{0};
std::atomic<bool> g_armed{false};

template <class F>
F next_symbol(const char* name) {
  return reinterpret_cast<F>(::dlsym(RTLD_NEXT, name));
}

bool is_regular(int fd) {
  struct stat st {};
  return fd > 2 && ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
}

bool is_directory(int fd) {
  struct stat st {};
  return ::fstat(fd, &st) == 0 && S_ISDIR(st.st_mode);
}

bool open_for_writing(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  return flags >= 0 && (flags & O_ACCMODE) != O_RDONLY;
}

/// How many of `n` bytes a write to `fd` may move now: n, fewer (a short write), or -1 with errno set.
long long allowance(int fd, std::size_t n) {
  if (!g_armed.load() || !is_regular(fd)) return static_cast<long long>(n);
  std::lock_guard<std::mutex> lock(g_mutex);
  std::size_t allowed = n;
  if (g_fault.max_chunk > 0 && allowed > g_fault.max_chunk) allowed = g_fault.max_chunk;
  if (g_fault.call == Call::write) {
    if (g_written >= g_fault.at_byte && n > 0) {
      ++g_failures;
      errno = g_fault.error;
      return -1;
    }
    if (g_written + allowed > g_fault.at_byte) allowed = static_cast<std::size_t>(g_fault.at_byte - g_written);
  }
  return static_cast<long long>(allowed);
}

void count(ssize_t moved) {
  if (moved <= 0 || !g_armed.load()) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_written += static_cast<std::uint64_t>(moved);
}

}  // namespace

void arm(const Fault& fault) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_fault = fault;
  g_written = 0;
  g_failures = 0;
  g_armed = true;
}

void disarm() {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_armed = false;
  g_fault = Fault{};
}

std::uint64_t bytes_written() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_written;
}

int failures_injected() { return g_failures.load(); }

}  // namespace lumx_faults

using namespace lumx_faults;

extern "C" ssize_t write(int fd, const void* buf, size_t n) {
  static const auto real = next_symbol<ssize_t (*)(int, const void*, size_t)>("write");
  const long long allowed = allowance(fd, n);
  if (allowed < 0) return -1;
  const ssize_t moved = real(fd, buf, static_cast<size_t>(allowed));
  if (is_regular(fd)) count(moved);
  return moved;
}

extern "C" ssize_t pwrite(int fd, const void* buf, size_t n, off_t offset) {
  static const auto real = next_symbol<ssize_t (*)(int, const void*, size_t, off_t)>("pwrite");
  const long long allowed = allowance(fd, n);
  if (allowed < 0) return -1;
  const ssize_t moved = real(fd, buf, static_cast<size_t>(allowed), offset);
  if (is_regular(fd)) count(moved);
  return moved;
}

extern "C" int fsync(int fd) {
  static const auto real = next_symbol<int (*)(int)>("fsync");
  if (g_armed.load()) {
    const Call c = g_fault.call;
    if ((c == Call::fsync_file && is_regular(fd)) || (c == Call::fsync_directory && is_directory(fd))) {
      ++g_failures;
      errno = g_fault.error;
      return -1;
    }
  }
  return real(fd);
}

extern "C" int close(int fd) {
  static const auto real = next_symbol<int (*)(int)>("close");
  if (g_armed.load() && g_fault.call == Call::close_file && is_regular(fd) && open_for_writing(fd)) {
    real(fd);  // Linux releases the descriptor even when close reports an error
    ++g_failures;
    errno = g_fault.error;
    return -1;
  }
  return real(fd);
}
