// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include "syscall_faults.h"

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <mutex>

#include <dlfcn.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace lumx_faults {
namespace {

// The fault and the counters, under one lock: writers may run on other threads than the test's.
std::mutex g_mutex;
Fault g_fault;
std::uint64_t g_written = 0, g_pwritten = 0;
int g_failures = 0, g_directory_syncs = 0, g_file_syncs = 0, g_closes = 0;
std::atomic<bool> g_armed{false};

template <class F>
F next_symbol(const char* name) {
  const auto f = reinterpret_cast<F>(::dlsym(RTLD_NEXT, name));
  if (!f) std::abort();  // the C library always defines these
  return f;
}

/// True (and errno set) if this call of an armed `call` is to fail; counts the calls.
bool fails(Call call, int& counter) {
  if (!g_armed.load()) return false;
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_fault.call != call) return false;
  ++counter;
  if (g_fault.nth != 0 && counter != g_fault.nth) return false;
  ++g_failures;
  errno = g_fault.error;
  return true;
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

void count(ssize_t moved, bool positioned) {
  if (moved <= 0 || !g_armed.load()) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_written += static_cast<std::uint64_t>(moved);
  if (positioned) g_pwritten += static_cast<std::uint64_t>(moved);
}

}  // namespace

void arm(const Fault& fault) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_fault = fault;
  g_written = g_pwritten = 0;
  g_failures = g_directory_syncs = g_file_syncs = g_closes = 0;
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

std::uint64_t bytes_pwritten() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_pwritten;
}

int directory_syncs() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_directory_syncs;
}

int failures_injected() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_failures;
}

}  // namespace lumx_faults

using namespace lumx_faults;

extern "C" ssize_t write(int fd, const void* buf, size_t n) {
  static const auto real = next_symbol<ssize_t (*)(int, const void*, size_t)>("write");
  const long long allowed = allowance(fd, n);
  if (allowed < 0) return -1;
  const ssize_t moved = real(fd, buf, static_cast<size_t>(allowed));
  if (is_regular(fd)) count(moved, false);
  return moved;
}

extern "C" ssize_t pwrite(int fd, const void* buf, size_t n, off_t offset) {
  static const auto real = next_symbol<ssize_t (*)(int, const void*, size_t, off_t)>("pwrite");
  const long long allowed = allowance(fd, n);
  if (allowed < 0) return -1;
  const ssize_t moved = real(fd, buf, static_cast<size_t>(allowed), offset);
  if (is_regular(fd)) count(moved, true);
  return moved;
}

// The name a caller built with 32-bit off_t and _FILE_OFFSET_BITS=64 reaches (the same call on x86-64).
extern "C" ssize_t pwrite64(int fd, const void* buf, size_t n, off_t offset) { return pwrite(fd, buf, n, offset); }

extern "C" int fsync(int fd) {
  static const auto real = next_symbol<int (*)(int)>("fsync");
  if (is_regular(fd) && fails(Call::fsync_file, g_file_syncs)) return -1;
  if (is_directory(fd) && fails(Call::fsync_directory, g_directory_syncs)) return -1;
  if (g_armed.load() && is_directory(fd)) {  // counted also when another fault is armed
    std::lock_guard<std::mutex> lock(g_mutex);
    if (g_fault.call != Call::fsync_directory) ++g_directory_syncs;
  }
  return real(fd);
}

extern "C" int close(int fd) {
  static const auto real = next_symbol<int (*)(int)>("close");
  if (is_regular(fd) && open_for_writing(fd) && fails(Call::close_file, g_closes)) {
    const int error = errno;
    real(fd);  // Linux releases the descriptor even when close reports an error
    errno = error;
    return -1;
  }
  return real(fd);
}
