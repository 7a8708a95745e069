// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// What the path-based fuzz targets share: the input written to a scratch file with a chosen extension, and
// a replay main() for builds without libFuzzer (tests/fuzz/replay_main.cpp), so that CTest runs every
// target over its seed corpus and the regression files in tests/data/fuzz/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace lumx_fuzz {

/// A per-process scratch file holding the input, named with `extension` (the readers choose formats by
/// extension first). Rewritten for every input; removed at exit.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& extension)
      : path_("/tmp/lumx_fuzz_" + std::to_string(::getpid()) + extension) {}
  ~ScratchFile() { std::remove(path_.c_str()); }
  const std::string& write(const std::uint8_t* data, std::size_t size) {
    std::FILE* f = std::fopen(path_.c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    return path_;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace lumx_fuzz
