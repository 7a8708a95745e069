// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Internal: a ZIP archive read with libzip, every entry checked against GldfLimits when it is opened —
// before anything is extracted. Errors are lumx::Error located as "archive!/entry".
#pragma once

#include <lumx/io/gldf_io.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

class ZipArchive {
 public:
  /// Opens `path` and checks every entry (names, sizes, ratio, encryption). Throws lumx::Error.
  ZipArchive(const std::string& path, const GldfLimits& limits);
  ~ZipArchive();
  ZipArchive(const ZipArchive&) = delete;
  ZipArchive& operator=(const ZipArchive&) = delete;

  /// Entry names in archive order, folders ("ldc/") excluded.
  const std::vector<std::string>& names() const { return names_; }
  bool contains(const std::string& name) const;
  /// The whole entry; its actual size must equal the size its header states. Throws lumx::Error.
  std::string read(const std::string& name) const;

 private:
  struct Entry {
    std::string name;
    std::uint64_t index = 0, size = 0;
  };
  std::string path_;
  void* zip_ = nullptr;  // zip_t
  std::vector<Entry> entries_;
  std::vector<std::string> names_;
};

}  // namespace detail
LUMX_NAMESPACE_END
