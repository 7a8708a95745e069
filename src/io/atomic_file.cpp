// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Atomic replacement of a file (hard-cases.md §4) and bounded whole-file reads.
#include <lumx/core/diagnostic.h>
#include <lumx/io/atomic_file.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

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

void write_file_atomically(const std::string& path, std::string_view bytes) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  // Unique temporary name in the same folder, so rename() is atomic on the same file system.
  std::random_device rd;
  const std::string tmp = (dir / ("." + target.filename().string() + ".tmp" + std::to_string(rd()))).string();
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
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) fail(path, "open folder for fsync", errno);
  if (::fsync(dfd) != 0 && errno != EINVAL) {  // EINVAL: the file system cannot sync folders
    const int err = errno;
    ::close(dfd);
    fail(path, "fsync folder", err);
  }
  ::close(dfd);
}

std::string read_file_bounded(const std::string& path, std::size_t max_bytes) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, "cannot open", ENOENT);
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "size", ec.value());
  if (size > max_bytes) {
    Diagnostic d;
    d.file = path;
    d.field = "file size";
    d.message = "file is " + std::to_string(size) + " bytes, above the limit of " + std::to_string(max_bytes);
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
