// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Atomic replacement of a file (hard-cases.md §4) and bounded whole-file reads.
#include <lumx/core/diagnostic.h>
#include <lumx/io/atomic_file.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <atomic>
#include <fstream>
#include <string>

#include <signal.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

LUMX_NAMESPACE_BEGIN
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& step, int err) {
  Diagnostic d;
  d.file = path;
  d.field = "file";
  d.message = step + ": " + std::strerror(err);
  throw Error(std::move(d));
}

}  // namespace

std::string temporary_sibling_name(const std::string& target) {
  namespace fs = std::filesystem;
  static std::atomic<unsigned> counter{0};
  const fs::path t(target);
  const fs::path dir = t.has_parent_path() ? t.parent_path() : fs::path(".");
  return (dir / ("." + t.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                 std::to_string(counter++)))
      .string();
}

void remove_stale_temporaries(const std::string& target) {
  namespace fs = std::filesystem;
  const fs::path t(target);
  const fs::path dir = t.has_parent_path() ? t.parent_path() : fs::path(".");
  const std::string prefix = "." + t.filename().string() + ".tmp-";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    // ".NAME.tmp-PID-N": a writer that still runs (or that we may not signal) keeps its temporary.
    const std::string rest = name.substr(prefix.size());
    const std::size_t dash = rest.find('-');
    if (dash == 0 || dash == std::string::npos || rest.find_first_not_of("0123456789-") != std::string::npos) continue;
    const long pid = std::strtol(rest.substr(0, dash).c_str(), nullptr, 10);
    if (pid <= 0 || pid == long(::getpid())) continue;
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;
    std::error_code ignored;
    fs::remove_all(it->path(), ignored);
  }
}

void write_file_atomically(const std::string& path, std::string_view bytes) {
  remove_stale_temporaries(path);
  const std::string tmp = temporary_sibling_name(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) fail(path, "create temporary file", errno);
  // Replacing a file keeps its permission bits.
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) ::fchmod(fd, st.st_mode & 07777);
  auto abandon = [&](const char* step, int err) {
    ::close(fd);
    ::unlink(tmp.c_str());
    fail(path, step, err);
  };
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      abandon("write", errno);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) abandon("fsync", errno);
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, "close", err);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, "rename", err);
  }
  // Make the rename itself durable.
  const std::filesystem::path target(path);
  sync_folder(target.has_parent_path() ? target.parent_path().string() : std::string("."), path, true);
}

void sync_folder(const std::string& folder, const std::string& reported_path, bool replaced) {
  const std::string prefix = replaced ? "the new version is in place, but its folder could not be synced: " : "";
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) fail(reported_path, prefix + "open folder for fsync", errno);
  if (::fsync(fd) != 0 && errno != EINVAL) {  // EINVAL: the file system cannot sync folders
    const int err = errno;
    ::close(fd);
    fail(reported_path, prefix + "fsync folder", err);
  }
  ::close(fd);
}

std::string read_file_bounded(const std::string& path, std::size_t max_bytes, const std::string& limit_name) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, "cannot open", ENOENT);
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "size", ec.value());
  if (size > max_bytes) {
    Diagnostic d;
    d.file = path;
    d.field = "file size";
    d.message = "file is " + std::to_string(size) + " bytes, above " +
                (limit_name.empty() ? "the limit" : limit_name) + " (" + std::to_string(max_bytes) + ")";
    throw Error(std::move(d));
  }
  std::ifstream f(path, std::ios::binary);
  if (!f) fail(path, "cannot open", errno ? errno : EACCES);
  std::string s(static_cast<std::size_t>(size), '\0');
  f.read(s.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::size_t>(f.gcount()) != size) fail(path, "read", EIO);
  return s;
}

LUMX_NAMESPACE_END
